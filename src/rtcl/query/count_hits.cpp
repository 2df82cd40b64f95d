// Accel's crossing queries (rtcl/accel.hpp): count and all_hits, on the
// plain 8-wide BVH (bvh, bvh-ploc, bvh-packet) with
// kernels/query/count_hits.cl, which always runs the robust level's
// watertight test with the crossing fill rule (kernels/shared/triangle.h,
// rtcl_crossing_hit8): a ray through a shared edge or vertex of a closed
// mesh crosses it once, a ray touching a silhouette 0 or 2 times.
//
// count on host arrays: HostBatches (32-byte rays in, one uint32 out).
// all_hits: that count pass over every ray, the per-ray segments (the
// count, at most max_hits_per_ray) prefix-summed on the host, then a
// listing pass in chunks of rays whose rays, segment offsets and hits each
// fit the device's largest buffer.
#include <algorithm>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/accel/accel_state.hpp"
#include "rtcl/error.hpp"
#include "rtcl/query/host_batches.hpp"

namespace rtcl {

namespace {

using detail::AccelAccess;

constexpr const char* kFile = "query/count_hits.cl";

void require_rays(const Rays& rays, const char* call) {
  if (rays.size() > 0 && rays.are_records() && !rays.records().data())
    throw Error(std::string(call) + ": null rays array");
}

// The count kernel over rays[0 .. n) into counts; mutex held.
cl::Event enqueue_count(const Accel& accel, const cl::Buffer& rays, const cl::Buffer& counts, std::size_t n,
                        const std::vector<cl::Event>& wait) {
  cl::Kernel& kernel = AccelAccess::kernel(accel, kFile, "count_hits_bvh", {}, 3, Precision::robust);
  kernel.setArg(0, rays);
  kernel.setArg(1, counts);
  kernel.setArg(2, static_cast<cl_uint>(n));
  return AccelAccess::launch(accel, kernel, n, wait);
}

// count on host arrays, arguments checked; mutex held.
void count_locked(const Accel& accel, const Rays& rays, std::uint32_t* counts) {
  HostBatches batches(accel.device(), rays.size(), sizeof(Ray), sizeof(std::uint32_t));
  run_rays(
      batches, rays, AccelAccess::staging(accel),
      [&](const cl::Buffer& in, const cl::Buffer& out, std::size_t n, const std::vector<cl::Event>& wait) {
        return enqueue_count(accel, in, out, n, wait);
      },
      counts);
}

}  // namespace

void Accel::count(const Rays& rays, std::span<std::uint32_t> counts) const {
  AccelAccess::require_plain_bvh8(*this, "count");
  require_rays(rays, "count");
  if (counts.size() != rays.size())
    throw Error("count: counts holds " + std::to_string(counts.size()) + " values for " +
                std::to_string(rays.size()) + " rays");
  if (rays.size() > 0 && !counts.data()) throw Error("count: null counts array");
  std::lock_guard lock(AccelAccess::mutex(*this));
  count_locked(*this, rays, counts.data());
}

std::vector<std::uint32_t> Accel::count(const Rays& rays) const {
  std::vector<std::uint32_t> counts(rays.size());
  count(rays, counts);
  return counts;
}

cl::Event Accel::count(const cl::Buffer& rays, const cl::Buffer& counts, std::size_t ray_count,
                       const std::vector<cl::Event>& wait) const {
  AccelAccess::require_plain_bvh8(*this, "count");
  return with_cl_errors([&] {
    if (ray_count > 0xffffffffu) throw Error("count: ray_count " + std::to_string(ray_count) + " exceeds 2^32-1");
    if (ray_count > 0 && (!rays() || !counts())) throw Error("count: null ray or count buffer");
    if (ray_count > 0) {
      std::size_t ray_bytes = rays.getInfo<CL_MEM_SIZE>(), count_bytes = counts.getInfo<CL_MEM_SIZE>();
      if (ray_bytes < ray_count * sizeof(Ray))
        throw Error("count: ray buffer holds " + std::to_string(ray_bytes / sizeof(Ray)) + " rays, " +
                    std::to_string(ray_count) + " requested");
      if (count_bytes < ray_count * sizeof(std::uint32_t))
        throw Error("count: count buffer holds " + std::to_string(count_bytes / sizeof(std::uint32_t)) +
                    " counts, " + std::to_string(ray_count) + " requested");
    }
    std::lock_guard lock(AccelAccess::mutex(*this));
    return enqueue_count(*this, rays, counts, ray_count, wait);
  });
}

AllHits Accel::all_hits(const Rays& rays, std::uint32_t max_hits_per_ray) const {
  AccelAccess::require_plain_bvh8(*this, "all_hits");
  require_rays(rays, "all_hits");
  if (max_hits_per_ray == 0)
    throw Error("all_hits: max_hits_per_ray is 0; it must be >= 1 (kAllHitsUnlimited: no cap)");
  const std::size_t ray_count = rays.size();
  AllHits result;
  result.offsets.assign(ray_count + 1, 0);
  std::lock_guard lock(AccelAccess::mutex(*this));
  std::vector<std::uint32_t> kept(ray_count);
  count_locked(*this, rays, kept.data());
  for (std::size_t i = 0; i < ray_count; ++i) {
    kept[i] = std::min(kept[i], max_hits_per_ray);
    result.offsets[i + 1] = result.offsets[i] + kept[i];
  }
  result.hits.resize(result.offsets[ray_count]);

  // Chunks of rays [first, end): rays, offsets (end - first + 1 uint32)
  // and hits each within the largest buffer, at most a HostBatches batch
  // of rays.
  const std::size_t max_bytes = device_.info().max_alloc_bytes;
  const std::size_t max_rays =
      std::max<std::size_t>(1, std::min({max_bytes / sizeof(Ray), max_bytes / sizeof(std::uint32_t) - 1,
                                         HostBatches::kDefaultMaxBatch}));
  const std::size_t max_hits = max_bytes / sizeof(Hit);
  std::vector<Ray> staging;
  std::vector<std::uint32_t> offsets;
  with_cl_errors([&] {
    for (std::size_t first = 0; first < ray_count;) {
      std::size_t end = first, hits = 0;
      while (end < ray_count && end - first < max_rays && hits + kept[end] <= max_hits) hits += kept[end++];
      if (end == first)
        throw Error("all_hits: ray " + std::to_string(first) + " has " + std::to_string(kept[first]) +
                    " crossings, more Hit records than the largest buffer of " + device_.info().name + " holds (" +
                    std::to_string(max_bytes) + " bytes); pass a max_hits_per_ray of at most " +
                    std::to_string(max_hits));
      if (hits > 0) {
        const std::size_t n = end - first;
        const Ray* chunk = rays.are_records() ? rays.records().data() + first : nullptr;
        if (!chunk) {
          staging.resize(n);
          rays.pack(first, staging);
          chunk = staging.data();
        }
        offsets.resize(n + 1);
        for (std::size_t k = 0; k <= n; ++k)
          offsets[k] = static_cast<std::uint32_t>(result.offsets[first + k] - result.offsets[first]);
        cl::Buffer ray_buffer = device_.upload(chunk, n * sizeof(Ray), "all_hits rays");
        cl::Buffer offset_buffer =
            device_.upload(offsets.data(), offsets.size() * sizeof(std::uint32_t), "all_hits offsets");
        cl::Buffer hit_buffer = device_.allocate(hits * sizeof(Hit), "all_hits hits");
        cl::Kernel& kernel = AccelAccess::kernel(*this, kFile, "list_hits_bvh", {}, 4, Precision::robust);
        kernel.setArg(0, ray_buffer);
        kernel.setArg(1, offset_buffer);
        kernel.setArg(2, hit_buffer);
        kernel.setArg(3, static_cast<cl_uint>(n));
        std::vector<cl::Event> done{AccelAccess::launch(*this, kernel, n, {})};
        device_.queue().enqueueReadBuffer(hit_buffer, CL_TRUE, 0, hits * sizeof(Hit),
                                          result.hits.data() + result.offsets[first], &done);
      }
      first = end;
    }
  });
  return result;
}

}  // namespace rtcl
