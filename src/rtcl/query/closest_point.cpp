// Accel's closest-point queries (rtcl/accel.hpp): the nearest surface point
// to each query point, on host arrays (batches through HostBatches) or on
// the caller's buffers, by kernels/query/closest_point.cl over the plain
// 8-wide BVH (bvh, bvh-ploc, bvh-packet).
#include <cmath>
#include <mutex>
#include <string>

#include "rtcl/accel.hpp"
#include "rtcl/accel/accel_state.hpp"
#include "rtcl/error.hpp"
#include "rtcl/opencl.hpp"
#include "rtcl/query/host_batches.hpp"

namespace rtcl {

namespace {

constexpr const char* kFile = "query/closest_point.cl";
constexpr const char* kKernel = "closest_point_bvh";
constexpr std::size_t kPointBytes = 3 * sizeof(float);
// The kernel's own arguments (points, out, count, max_distance) come first.
constexpr cl_uint kFirstStructureArg = 4;

void check_max_distance(float max_distance, const char* call) {
  if (std::isnan(max_distance) || max_distance < 0.0f)
    throw Error(std::string(call) + ": max_distance " + std::to_string(max_distance) +
                " must be >= 0 (+inf: unlimited)");
}

void check_points(const Points& points, const char* call) {
  std::span<const float> xyz = points.xyz();
  for (std::size_t i = 0; i < xyz.size(); ++i)
    if (!std::isfinite(xyz[i]))
      throw Error(std::string(call) + ": points[" + std::to_string(i / 3) + "] has a NaN or infinite coordinate");
}

// Enqueues the kernel; the caller holds the structure's lock.
cl::Event enqueue_locked(const Accel& accel, const cl::Buffer& points, const cl::Buffer& out, std::size_t count,
                         float max_distance, const std::vector<cl::Event>& wait) {
  const Device& device = accel.device();
  return with_cl_errors([&] {
    cl::Event done;
    if (count == 0) {
      device.queue().enqueueMarkerWithWaitList(&wait, &done);
      return done;
    }
    // Built at the robust level whatever the structure's: without
    // -cl-fast-relaxed-math, so that the pruning's rounding margin holds.
    cl::Kernel& kernel =
        detail::AccelAccess::kernel(accel, kFile, kKernel, {}, kFirstStructureArg, Precision::robust);
    kernel.setArg(0, points);
    kernel.setArg(1, out);
    kernel.setArg(2, static_cast<cl_uint>(count));
    kernel.setArg(3, max_distance);
    return detail::AccelAccess::launch(accel, kernel, count, wait);
  });
}

// The host-array query behind closest_points and distance; `call` names it
// in errors.
void closest_points_on_host(const Accel& accel, const Points& points, std::span<PointHit> out, float max_distance,
                            const char* call) {
  detail::AccelAccess::require_plain_bvh8(accel, call);
  if (out.size() != points.size())
    throw Error(std::string(call) + ": out holds " + std::to_string(out.size()) + " records for " +
                std::to_string(points.size()) + " points");
  if (points.size() > 0 && !out.data()) throw Error(std::string(call) + ": null out array");
  if (points.size() > 0 && !points.xyz().data()) throw Error(std::string(call) + ": null points array");
  check_max_distance(max_distance, call);
  check_points(points, call);
  HostBatches batches(accel.device(), points.size(), kPointBytes, sizeof(PointHit));
  std::lock_guard lock(detail::AccelAccess::mutex(accel));
  batches.run(points.xyz().data(),
              [&](const cl::Buffer& in, const cl::Buffer& result, std::size_t n, const std::vector<cl::Event>& wait) {
                return enqueue_locked(accel, in, result, n, max_distance, wait);
              },
              out.data());
}

}  // namespace

void Accel::closest_points(const Points& points, std::span<PointHit> out, float max_distance) const {
  closest_points_on_host(*this, points, out, max_distance, "closest_points");
}

std::vector<PointHit> Accel::closest_points(const Points& points, float max_distance) const {
  std::vector<PointHit> out(points.size());
  closest_points_on_host(*this, points, out, max_distance, "closest_points");
  return out;
}

std::vector<float> Accel::distance(const Points& points) const {
  std::vector<PointHit> hits(points.size());
  closest_points_on_host(*this, points, hits, kUnlimitedDistance, "distance");
  std::vector<float> d(hits.size());
  for (std::size_t i = 0; i < hits.size(); ++i) d[i] = hits[i].distance;
  return d;
}

cl::Event Accel::closest_points(const cl::Buffer& points, const cl::Buffer& out, std::size_t point_count,
                                float max_distance, const std::vector<cl::Event>& wait) const {
  const char* call = "closest_points";
  detail::AccelAccess::require_plain_bvh8(*this, call);
  check_max_distance(max_distance, call);
  return with_cl_errors([&] {
    if (point_count > 0xffffffffu)
      throw Error(std::string(call) + ": point_count " + std::to_string(point_count) + " exceeds 2^32-1");
    if (point_count > 0 && (!points() || !out())) throw Error(std::string(call) + ": null points or out buffer");
    if (point_count > 0) {
      std::size_t in_bytes = points.getInfo<CL_MEM_SIZE>(), out_bytes = out.getInfo<CL_MEM_SIZE>();
      if (in_bytes < point_count * kPointBytes)
        throw Error(std::string(call) + ": points buffer holds " + std::to_string(in_bytes / kPointBytes) +
                    " points, " + std::to_string(point_count) + " requested");
      if (out_bytes < point_count * sizeof(PointHit))
        throw Error(std::string(call) + ": out buffer holds " + std::to_string(out_bytes / sizeof(PointHit)) +
                    " records, " + std::to_string(point_count) + " requested");
    }
    std::lock_guard lock(detail::AccelAccess::mutex(*this));
    return enqueue_locked(*this, points, out, point_count, max_distance, wait);
  });
}

}  // namespace rtcl
