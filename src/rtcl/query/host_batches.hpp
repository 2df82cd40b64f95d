// Host-array queries in batches (internal): any number of items (rays or
// points) goes through device buffers that each fit the device's largest
// allocation (DeviceInfo::max_alloc_bytes, lowered by RTCL_MAX_ALLOC_BYTES).
//
// Two ways, chosen by the device:
// - CPU devices share the host's memory: each batch's input and output
//   are buffers on the caller's own arrays (CL_MEM_USE_HOST_PTR), the
//   output mapped to make it visible: no copies.
// - Other devices: two slots of device buffers; batch b uploads into slot
//   b % 2 while the device may still trace batch b - 1, then traces and
//   reads back without blocking, so that the host prepares the next batch
//   while the device works. RTCL_HOST_ARRAYS=copy selects this way on every
//   device (the tests run both on PoCL).
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "rtcl/device.hpp"

namespace rtcl {

class HostBatches {
 public:
  // `count` items of in_item_bytes input and out_item_bytes output each;
  // at most max_batch_items per batch (0: only the device's limit).
  HostBatches(const Device& device, std::size_t count, std::size_t in_item_bytes, std::size_t out_item_bytes,
              std::size_t max_batch_items = kDefaultMaxBatch);

  // Items per batch (the last may hold fewer).
  std::size_t batch_items() const { return batch_items_; }

  // The input of items [first, first + n): either a pointer into the
  // caller's array (returned as is), or packed into `staging` (room for n
  // items) and `staging` returned.
  using Input = std::function<const void*(std::size_t first, std::size_t n, void* staging)>;
  // Enqueues the query of n items from `in` into `out` after `wait` (on
  // the device's queue); returns the event that ends it.
  using Enqueue = std::function<cl::Event(const cl::Buffer& in, const cl::Buffer& out, std::size_t n,
                                          const std::vector<cl::Event>& wait)>;
  // Runs every batch; the output of item i lands at output + i *
  // out_item_bytes. Returns when all of it is there.
  void run(const Input& input, const Enqueue& enqueue, void* output) const;

  // 1M items: big enough to amortise a launch, small enough for two slots
  // of buffers on any device.
  static constexpr std::size_t kDefaultMaxBatch = std::size_t{1} << 20;

 private:
  void run_shared(const Input& input, const Enqueue& enqueue, void* output) const;
  void run_copied(const Input& input, const Enqueue& enqueue, void* output) const;

  Device device_;
  std::size_t count_, in_bytes_, out_bytes_, batch_items_;
  bool shared_memory_;
};

}  // namespace rtcl
