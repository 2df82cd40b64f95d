// Host-array queries in batches (internal): any number of items (rays or
// points) goes through device buffers that each fit the device's largest
// allocation (DeviceInfo::max_alloc_bytes, lowered by RTCL_MAX_ALLOC_BYTES).
//
// The input is either in place (the caller's contiguous records) or packed
// batch by batch into staging memory that the structure keeps between calls
// (separate origin and direction arrays into Ray records): allocating and
// first touching fresh memory for every call costs more than a trace.
//
// Two ways, chosen by the device:
// - CPU devices share the host's memory: each batch's input and output are
//   buffers on the caller's own arrays or the staging memory
//   (CL_MEM_USE_HOST_PTR), the output mapped to make it visible: no copies.
//   Packed batches alternate between two halves of the staging memory, so
//   that the host packs batch b + 1 while the device traces batch b.
// - Other devices: two slots of device buffers; batch b uploads into slot
//   b % 2 through a transfer queue of its own while the device's queue may
//   still trace batch b - 1, then traces and reads back without blocking
//   (events order each batch's steps), so that copies overlap traces and
//   the host prepares the next batch while the device works. RTCL_HOST_ARRAYS=copy selects this way on every
//   device (the tests run both on PoCL).
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "rtcl/device.hpp"
#include "rtcl/queries.hpp"

namespace rtcl {

class HostBatches {
 public:
  // Enqueues the query of n items from `in` into `out` after `wait` (on
  // the device's queue); returns the event that ends it.
  using Enqueue = std::function<cl::Event(const cl::Buffer& in, const cl::Buffer& out, std::size_t n,
                                          const std::vector<cl::Event>& wait)>;
  // Writes items [first, first + n) of the input into `to` (room for n
  // items of in_item_bytes).
  using Pack = std::function<void(std::size_t first, std::size_t n, void* to)>;

  // `count` items of in_item_bytes input and out_item_bytes output each.
  HostBatches(const Device& device, std::size_t count, std::size_t in_item_bytes, std::size_t out_item_bytes);

  // Every batch of input in place (item i at in + i * in_item_bytes); the
  // output of item i lands at output + i * out_item_bytes. Returns when all
  // of it is there.
  void run(const void* in, const Enqueue& enqueue, void* output) const;
  // The same with the input packed batch by batch into `staging` (grown to
  // at most 2 * kPackedBatch items; the caller keeps it between calls and
  // holds it alone during the call).
  void run(const Pack& pack, std::vector<unsigned char>& staging, const Enqueue& enqueue, void* output) const;

  // Items per batch in place: big enough to amortise a launch, small enough
  // for two slots of buffers on any device.
  static constexpr std::size_t kDefaultMaxBatch = std::size_t{1} << 20;
  // Items per packed batch: staging of 2 x 2 MiB for 32-byte rays.
  static constexpr std::size_t kPackedBatch = std::size_t{1} << 16;

 private:
  // The input of batch `index` (items [first, first + n)), in slot `slot`.
  using Source = std::function<const void*(std::size_t first, std::size_t n, std::size_t slot)>;
  void run_batches(std::size_t batch, bool packed, const Source& source, const Enqueue& enqueue,
                   void* output) const;
  void run_shared(std::size_t batch, bool packed, const Source& source, const Enqueue& enqueue, void* output) const;
  void run_copied(std::size_t batch, const Source& source, const Enqueue& enqueue, void* output) const;
  std::size_t batch_limit(std::size_t wanted) const;

  Device device_;
  std::size_t count_, in_bytes_, out_bytes_;
  bool shared_memory_;
};

// Rays as Ray records through `batches`: in place when they are records,
// else packed into `staging`.
void run_rays(const HostBatches& batches, const Rays& rays, std::vector<unsigned char>& staging,
              const HostBatches::Enqueue& enqueue, void* output);

}  // namespace rtcl
