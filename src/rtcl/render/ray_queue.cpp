#include "rtcl/render/ray_queue.hpp"

#include <algorithm>

#include "rtcl/error.hpp"
#include "rtcl/render/launch.hpp"

namespace rtcl {

namespace {

const std::vector<cl::Event>* wait_list(const std::vector<cl::Event>& wait) { return wait.empty() ? nullptr : &wait; }

std::size_t chunks(std::size_t slots) { return (slots + RTCL_SCAN_CHUNK - 1) / RTCL_SCAN_CHUNK; }

// count_flags, scan_counts and a scatter kernel whose first three arguments
// are (flags, slot_count, counts) and whose others the caller has set.
cl::Event enqueue_compaction(const Device& device, cl::Kernel& count, cl::Kernel& scan, cl::Kernel& scatter,
                             const cl::Buffer& flags, std::size_t slot_count, GrowingBuffer& chunk_counts,
                             const cl::Buffer& totals, std::size_t at, const std::vector<cl::Event>& wait,
                             cl::Event* first) {
  return with_cl_errors([&] {
    std::size_t n_chunks = std::max<std::size_t>(chunks(slot_count), 1);
    const cl::Buffer& counts = chunk_counts.reserve(device, n_chunks);
    auto slots = static_cast<cl_uint>(slot_count);
    cl::CommandQueue& queue = device.queue();
    cl::Event counted, scanned;
    count.setArg(0, flags);
    count.setArg(1, slots);
    count.setArg(2, counts);
    scan.setArg(0, counts);
    scan.setArg(1, static_cast<cl_uint>(slot_count == 0 ? 0 : n_chunks));
    scan.setArg(2, totals);
    scan.setArg(3, static_cast<cl_uint>(at));
    scatter.setArg(0, flags);
    scatter.setArg(1, slots);
    scatter.setArg(2, counts);
    std::vector<cl::Event> after;
    if (slot_count > 0) {
      counted = launch(device, count, n_chunks, wait);
      after = {counted};
    } else {
      after = wait;
    }
    queue.enqueueNDRangeKernel(scan, cl::NullRange, cl::NDRange(1), cl::NullRange, wait_list(after), &scanned);
    if (first) *first = slot_count > 0 ? counted : scanned;
    if (slot_count == 0) return scanned;
    std::vector<cl::Event> scan_done{scanned};
    return launch(device, scatter, n_chunks, scan_done);
  });
}

}  // namespace

const cl::Buffer& GrowingBuffer::reserve(const Device& device, std::size_t count) {
  if (count > capacity_ || capacity_ == 0) {
    std::size_t grown = std::max<std::size_t>({count, capacity_ + capacity_ / 2, 1});
    buffer_ = device.allocate(grown * record_bytes_, what_);
    capacity_ = grown;
  }
  return buffer_;
}

void SpawnSlots::reserve(const Device& device, std::size_t slots) {
  rays.reserve(device, slots);
  paths.reserve(device, slots);
  flags.reserve(device, slots);
  count = slots;
}

void ShadowSlots::reserve(const Device& device, std::size_t slots) {
  rays.reserve(device, slots);
  weights.reserve(device, slots);
  flags.reserve(device, slots);
  index.reserve(device, slots);
  count = slots;
}

RayQueue::RayQueue(const Device& device) : device_(device) {
  with_cl_errors([&] {
    cl::Program generate = device_.program("render/generate.cl", {});
    cl::Program compact = device_.program("render/compact.cl", {});
    generate_ = cl::Kernel(generate, "generate_camera_rays");
    generate_at_ = cl::Kernel(generate, "generate_camera_rays_at");
    count_ = cl::Kernel(compact, "count_flags");
    scan_ = cl::Kernel(compact, "scan_counts");
    scatter_ = cl::Kernel(compact, "compact_spawned_rays");
  });
}

void RayQueue::specialise_generation(const std::vector<std::string>& defines) {
  with_cl_errors([&] {
    cl::Program generate = device_.program("render/generate.cl", defines);
    generate_ = cl::Kernel(generate, "generate_camera_rays");
    generate_at_ = cl::Kernel(generate, "generate_camera_rays_at");
  });
}

cl::Event RayQueue::generate_camera_rays(const cl::Buffer& camera, std::uint32_t first, std::uint32_t count,
                                         std::uint32_t sample, std::uint32_t spp, std::uint32_t x0,
                                         std::uint32_t y0, std::uint32_t rw, std::uint32_t rh,
                                         const std::vector<cl::Event>& wait) {
  rays_.reserve(device_, count);
  paths_.reserve(device_, count);
  size_ = count;
  return with_cl_errors([&] {
    generate_.setArg(0, rays_.buffer());
    generate_.setArg(1, paths_.buffer());
    generate_.setArg(2, camera);
    generate_.setArg(3, static_cast<cl_uint>(first));
    generate_.setArg(4, static_cast<cl_uint>(count));
    generate_.setArg(5, static_cast<cl_uint>(sample));
    generate_.setArg(6, static_cast<cl_uint>(spp));
    generate_.setArg(7, static_cast<cl_uint>(x0));
    generate_.setArg(8, static_cast<cl_uint>(y0));
    generate_.setArg(9, static_cast<cl_uint>(rw));
    generate_.setArg(10, static_cast<cl_uint>(rh));
    return launch(device_, generate_, std::max<std::uint32_t>(count, 1), wait);
  });
}

cl::Event RayQueue::generate_camera_rays_at(const cl::Buffer& camera, const cl::Buffer& pixels, std::uint32_t first,
                                            std::uint32_t count, std::uint32_t spp,
                                            const std::vector<cl::Event>& wait) {
  rays_.reserve(device_, count);
  paths_.reserve(device_, count);
  size_ = count;
  return with_cl_errors([&] {
    generate_at_.setArg(0, rays_.buffer());
    generate_at_.setArg(1, paths_.buffer());
    generate_at_.setArg(2, camera);
    generate_at_.setArg(3, pixels);
    generate_at_.setArg(4, static_cast<cl_uint>(first));
    generate_at_.setArg(5, static_cast<cl_uint>(count));
    generate_at_.setArg(6, static_cast<cl_uint>(spp));
    return launch(device_, generate_at_, std::max<std::uint32_t>(count, 1), wait);
  });
}

void RayQueue::assign(const std::vector<Ray>& rays, const std::vector<PathState>& paths) {
  if (rays.size() != paths.size()) throw Error("ray queue: " + std::to_string(rays.size()) + " rays but " +
                                               std::to_string(paths.size()) + " path states");
  rays_.reserve(device_, rays.size());
  paths_.reserve(device_, paths.size());
  size_ = rays.size();
  if (rays.empty()) return;
  with_cl_errors([&] {
    device_.queue().enqueueWriteBuffer(rays_.buffer(), CL_TRUE, 0, rays.size() * sizeof(Ray), rays.data());
    device_.queue().enqueueWriteBuffer(paths_.buffer(), CL_TRUE, 0, paths.size() * sizeof(PathState), paths.data());
  });
}

void RayQueue::read(std::vector<Ray>& rays, std::vector<PathState>& paths, const std::vector<cl::Event>& wait) const {
  rays.resize(size_);
  paths.resize(size_);
  if (size_ == 0) return;
  with_cl_errors([&] {
    device_.queue().enqueueReadBuffer(rays_.buffer(), CL_TRUE, 0, size_ * sizeof(Ray), rays.data(), wait_list(wait));
    device_.queue().enqueueReadBuffer(paths_.buffer(), CL_TRUE, 0, size_ * sizeof(PathState), paths.data());
  });
}

cl::Event RayQueue::compact_from(const SpawnSlots& slots, const cl::Buffer& totals, std::size_t at,
                                 const std::vector<cl::Event>& wait, cl::Event* first) {
  rays_.reserve(device_, slots.count);
  paths_.reserve(device_, slots.count);
  return with_cl_errors([&] {
    scatter_.setArg(3, slots.rays.buffer());
    scatter_.setArg(4, slots.paths.buffer());
    scatter_.setArg(5, rays_.buffer());
    scatter_.setArg(6, paths_.buffer());
    return enqueue_compaction(device_, count_, scan_, scatter_, slots.flags.buffer(), slots.count, chunk_counts_,
                              totals, at, wait, first);
  });
}

ShadowQueue::ShadowQueue(const Device& device) : device_(device) {
  with_cl_errors([&] {
    cl::Program compact = device_.program("render/compact.cl", {});
    count_ = cl::Kernel(compact, "count_flags");
    scan_ = cl::Kernel(compact, "scan_counts");
    scatter_ = cl::Kernel(compact, "compact_shadow_rays");
  });
}

cl::Event ShadowQueue::compact_from(const ShadowSlots& slots, const cl::Buffer& totals, std::size_t at,
                                    const std::vector<cl::Event>& wait, cl::Event* first) {
  rays_.reserve(device_, slots.count);
  hits_.reserve(device_, slots.count);
  return with_cl_errors([&] {
    scatter_.setArg(3, slots.rays.buffer());
    scatter_.setArg(4, rays_.buffer());
    scatter_.setArg(5, slots.index.buffer());
    return enqueue_compaction(device_, count_, scan_, scatter_, slots.flags.buffer(), slots.count, chunk_counts_,
                              totals, at, wait, first);
  });
}

}  // namespace rtcl
