#include "rtcl/accel/ray_sort.hpp"

#include <algorithm>
#include <cstdint>
#include <string>

#include "rtcl/error.hpp"

namespace rtcl {

namespace {

int checked_origin_bits(int bits) {
  if (bits < 0 || bits > 4) throw Error("ray sort: origin_bits " + std::to_string(bits) + " is not in 0 .. 4");
  return bits;
}

// Rays per chunk at least, and chunks per compute unit at most: enough
// chunks to share the passes among the cores, few enough that the prefix
// sum over (bucket, chunk), serial in its length, stays a small part of
// the sort.
constexpr std::size_t kMinChunkRays = 4096;
constexpr std::size_t kChunksPerUnit = 4;

}  // namespace

RaySort::RaySort(const Device& device, const Aabb& bounds, int origin_bits)
    : device_(device), buckets_(std::size_t{1} << (3 * checked_origin_bits(origin_bits) + 3)) {
  if (!bounds.empty()) {
    const float cells = static_cast<float>(1u << origin_bits);
    const glm::vec3 extent = bounds.upper - bounds.lower;
    lo_ = {{bounds.lower.x, bounds.lower.y, bounds.lower.z, 0.0f}};
    scale_ = {{extent.x > 0 ? cells / extent.x : 0.0f, extent.y > 0 ? cells / extent.y : 0.0f,
               extent.z > 0 ? cells / extent.z : 0.0f, 0.0f}};
  }
  with_cl_errors([&] {
    cl::Program program = device_.program("accel/ray_sort.cl", {"RTCL_SORT_ORIGIN_BITS=" + std::to_string(origin_bits)});
    count_ = cl::Kernel(program, "ray_sort_count");
    offsets_ = cl::Kernel(program, "ray_sort_offsets");
    scatter_ = cl::Kernel(program, "ray_sort_scatter");
  });
  totals_ = device_.allocate(buckets_ * sizeof(std::uint32_t), "ray sort totals");
}

void RaySort::reserve(std::size_t ray_count, std::size_t chunks) {
  if (ray_count > ray_capacity_) {
    keys_ = device_.allocate(ray_count * sizeof(std::uint16_t), "ray sort keys");
    order_ = device_.allocate(ray_count * sizeof(std::uint32_t), "ray order");
    ray_capacity_ = ray_count;
  }
  if (chunks > chunk_capacity_) {
    counts_ = device_.allocate(chunks * buckets_ * sizeof(std::uint32_t), "ray sort counts");
    chunk_capacity_ = chunks;
  }
}

std::vector<cl::Event> RaySort::enqueue(const cl::Buffer& rays, std::size_t ray_count,
                                        const std::vector<cl::Event>& wait) {
  if (ray_count == 0) throw Error("ray sort: no rays to sort");
  return with_cl_errors([&] {
    const std::size_t units = std::max<std::size_t>(1, device_.info().compute_units);
    const std::size_t chunks =
        std::clamp<std::size_t>((ray_count + kMinChunkRays - 1) / kMinChunkRays, 1, kChunksPerUnit * units);
    const std::size_t chunk = (ray_count + chunks - 1) / chunks;
    reserve(ray_count, chunks);
    const auto count = static_cast<cl_uint>(ray_count), chunk_rays = static_cast<cl_uint>(chunk);
    count_.setArg(0, rays), count_.setArg(1, count), count_.setArg(2, chunk_rays), count_.setArg(3, lo_);
    count_.setArg(4, scale_), count_.setArg(5, counts_), count_.setArg(6, keys_);
    offsets_.setArg(0, counts_), offsets_.setArg(1, static_cast<cl_uint>(chunks)), offsets_.setArg(2, totals_);
    scatter_.setArg(0, keys_), scatter_.setArg(1, count), scatter_.setArg(2, chunk_rays);
    scatter_.setArg(3, counts_), scatter_.setArg(4, totals_), scatter_.setArg(5, order_);
    std::vector<cl::Event> events(3);
    cl::CommandQueue& queue = device_.queue();
    queue.enqueueNDRangeKernel(count_, cl::NullRange, cl::NDRange(chunks), cl::NDRange(1),
                               wait.empty() ? nullptr : &wait, &events[0]);
    queue.enqueueNDRangeKernel(offsets_, cl::NullRange, cl::NDRange(buckets_), cl::NullRange, nullptr, &events[1]);
    queue.enqueueNDRangeKernel(scatter_, cl::NullRange, cl::NDRange(chunks), cl::NDRange(1), nullptr, &events[2]);
    return events;
  });
}

}  // namespace rtcl
