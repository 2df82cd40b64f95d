// The wavefront renderer's ray queues on the device. A queue holds Ray
// records (the layout every trace kernel reads) and, in parallel, a
// PathState per ray (pixel, depth, path weight). Camera rays are generated in
// screen-tile order, so consecutive work-items and packets of 8 are coherent.
// The shade stage writes candidate rays into fixed slots with a flag each;
// compaction (a chunked prefix sum on the device, order preserving) turns
// the flagged slots into the next dense queue.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "rtcl/device.hpp"
#include "rtcl/render/render_layouts.hpp"

namespace rtcl {

// A device buffer of records that grows (by at least half, contents lost) to
// hold a requested count; never shrinks.
class GrowingBuffer {
 public:
  GrowingBuffer(const char* what, std::size_t record_bytes) : what_(what), record_bytes_(record_bytes) {}
  const cl::Buffer& reserve(const Device& device, std::size_t count);
  const cl::Buffer& buffer() const { return buffer_; }
  std::size_t bytes() const { return capacity_ * record_bytes_; }

 private:
  const char* what_;
  std::size_t record_bytes_;
  std::size_t capacity_ = 0;
  cl::Buffer buffer_;
};

// Slots for reflected and refracted rays: 2 per shaded ray (2i reflection,
// 2i + 1 refraction), flag = RTCL_SLOT_* kind.
struct SpawnSlots {
  GrowingBuffer rays{"spawn slot rays", sizeof(Ray)}, paths{"spawn slot paths", sizeof(PathState)},
      flags{"spawn slot flags", RTCL_FLAG_BYTES};
  std::size_t count = 0;
  void reserve(const Device& device, std::size_t slots);
};

// Slots for shadow rays: light_count per shaded ray, with the contribution
// each adds when unoccluded and, after compaction, its shadow-queue index.
struct ShadowSlots {
  GrowingBuffer rays{"shadow slot rays", sizeof(Ray)}, weights{"shadow slot weights", RTCL_RADIANCE_BYTES},
      flags{"shadow slot flags", RTCL_FLAG_BYTES}, index{"shadow slot index", RTCL_FLAG_BYTES};
  std::size_t count = 0;
  void reserve(const Device& device, std::size_t slots);
};

// The number of rays a compaction produced (read back from the device).
struct CompactCounts {
  std::uint32_t rays = 0, refracted = 0;
};

class RayQueue {
 public:
  explicit RayQueue(const Device& device);

  std::size_t size() const { return size_; }
  void set_size(std::size_t size) { size_ = size; }
  const cl::Buffer& rays() const { return rays_.buffer(); }
  const cl::Buffer& paths() const { return paths_.buffer(); }
  std::size_t bytes() const { return rays_.bytes() + paths_.bytes(); }

  // Rebuilds the camera-ray kernel with these -D options (generate.cl: a
  // thin lens). The queue starts with none.
  void specialise_generation(const std::vector<std::string>& defines);

  // Fills the queue with camera rays first .. first + count - 1 of the
  // screen-tile order of the image region (x0, y0, rw, rh) for sample
  // `sample` of `spp` (camera: a DeviceCamera); paths carry the pixel's
  // row-major index inside the region.
  cl::Event generate_camera_rays(const cl::Buffer& camera, std::uint32_t first, std::uint32_t count,
                                 std::uint32_t sample, std::uint32_t spp, std::uint32_t x0, std::uint32_t y0,
                                 std::uint32_t rw, std::uint32_t rh, const std::vector<cl::Event>& wait);

  // Fills the queue with the camera rays of slots first .. first + count - 1
  // of a pixel list (a device buffer of y * width + x, each pixel listed
  // once): slot k is sample k % spp of pixel k / spp of the list; paths
  // carry the slot.
  cl::Event generate_camera_rays_at(const cl::Buffer& camera, const cl::Buffer& pixels, std::uint32_t first,
                                    std::uint32_t count, std::uint32_t spp, const std::vector<cl::Event>& wait);

  // Replaces the contents with these rays and paths (same length).
  void assign(const std::vector<Ray>& rays, const std::vector<PathState>& paths);
  // The rays and paths queued now (blocking read, after `wait`).
  void read(std::vector<Ray>& rays, std::vector<PathState>& paths, const std::vector<cl::Event>& wait) const;

  // Replaces the contents with the flagged spawn slots, in slot order. The
  // counts land in totals[at] (rays) and totals[at + 1] (refracted rays) on
  // the device; the caller reads them and calls set_size. Returns the last
  // kernel's event; *first (when given) receives the first kernel's.
  cl::Event compact_from(const SpawnSlots& slots, const cl::Buffer& totals, std::size_t at,
                         const std::vector<cl::Event>& wait, cl::Event* first = nullptr);

 private:
  Device device_;
  GrowingBuffer rays_{"ray queue", sizeof(Ray)}, paths_{"path states", sizeof(PathState)}, chunk_counts_{"compaction counts", RTCL_CHUNK_COUNT_BYTES};
  std::size_t size_ = 0;
  cl::Kernel generate_, generate_at_, count_, scan_, scatter_;
};

// The dense queue of shadow rays and their any-hit answers.
class ShadowQueue {
 public:
  explicit ShadowQueue(const Device& device);

  std::size_t size() const { return size_; }
  void set_size(std::size_t size) { size_ = size; }
  const cl::Buffer& rays() const { return rays_.buffer(); }
  const cl::Buffer& hits() const { return hits_.buffer(); }
  std::size_t bytes() const { return rays_.bytes() + hits_.bytes(); }

  // Like RayQueue::compact_from; also records each flagged slot's index.
  cl::Event compact_from(const ShadowSlots& slots, const cl::Buffer& totals, std::size_t at,
                         const std::vector<cl::Event>& wait, cl::Event* first = nullptr);

 private:
  Device device_;
  GrowingBuffer rays_{"shadow queue", sizeof(Ray)}, hits_{"shadow hits", sizeof(Hit)}, chunk_counts_{"compaction counts", RTCL_CHUNK_COUNT_BYTES};
  std::size_t size_ = 0;
  cl::Kernel count_, scan_, scatter_;
};

}  // namespace rtcl
