#include "rtcl/query/host_batches.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>

#include "rtcl/error.hpp"

namespace rtcl {

namespace {

bool copy_forced() {
  const char* mode = std::getenv("RTCL_HOST_ARRAYS");
  return mode && std::string(mode) == "copy";
}

}  // namespace

HostBatches::HostBatches(const Device& device, std::size_t count, std::size_t in_item_bytes,
                         std::size_t out_item_bytes)
    : device_(device),
      count_(count),
      in_bytes_(in_item_bytes),
      out_bytes_(out_item_bytes),
      shared_memory_(device.info().type == "cpu" && !copy_forced()) {
  const std::size_t largest = std::max(in_item_bytes, out_item_bytes);
  if (device.info().max_alloc_bytes < largest)
    throw Error("device " + device.info().name + " allows buffers of " + std::to_string(device.info().max_alloc_bytes) +
                " bytes, fewer than one query record of " + std::to_string(largest));
}

std::size_t HostBatches::batch_limit(std::size_t wanted) const {
  const std::size_t fit = device_.info().max_alloc_bytes / std::max(in_bytes_, out_bytes_);
  return std::max<std::size_t>(1, std::min({fit, wanted, count_}));
}

void HostBatches::run(const void* in, const Enqueue& enqueue, void* output) const {
  const auto* bytes = static_cast<const unsigned char*>(in);
  run_batches(batch_limit(kDefaultMaxBatch), false,
              [&](std::size_t first, std::size_t, std::size_t) { return bytes + first * in_bytes_; }, enqueue, output);
}

void HostBatches::run(const Pack& pack, std::vector<unsigned char>& staging, const Enqueue& enqueue,
                      void* output) const {
  const std::size_t batch = batch_limit(kPackedBatch);
  const std::size_t slot_bytes = batch * in_bytes_;
  if (count_ > 0 && staging.size() < 2 * slot_bytes) staging.resize(2 * slot_bytes);
  run_batches(batch, true,
              [&](std::size_t first, std::size_t n, std::size_t slot) -> const void* {
                unsigned char* to = staging.data() + slot * slot_bytes;
                pack(first, n, to);
                return to;
              },
              enqueue, output);
}

void HostBatches::run_batches(std::size_t batch, bool packed, const Source& source, const Enqueue& enqueue,
                              void* output) const {
  if (count_ == 0) return;
  with_cl_errors([&] {
    try {
      if (shared_memory_)
        run_shared(batch, packed, source, enqueue, output);
      else
        run_copied(batch, source, enqueue, output);
    } catch (...) {
      device_.queue().finish();  // no command may still read or write the caller's arrays
      throw;
    }
  });
}

void HostBatches::run_shared(std::size_t batch, bool packed, const Source& source, const Enqueue& enqueue,
                             void* output) const {
  const cl::Context& context = device_.context();
  cl::CommandQueue& queue = device_.queue();
  auto* out = static_cast<unsigned char*>(output);
  struct Mapped {
    cl::Buffer buffer;
    void* pointer;
    unsigned char* target;
    std::size_t bytes;
    cl::Event ready;
  };
  std::vector<Mapped> maps;
  cl::Event slot_done[2];  // the kernel that last read each half of the staging memory
  std::size_t b = 0;
  for (std::size_t first = 0; first < count_; first += batch, ++b) {
    const std::size_t n = std::min(batch, count_ - first);
    const std::size_t slot = b % 2;
    if (packed && slot_done[slot]()) slot_done[slot].wait();
    const void* src = source(first, n, slot);
    cl::Buffer in(context, CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR, n * in_bytes_, const_cast<void*>(src));
    cl::Buffer result(context, CL_MEM_WRITE_ONLY | CL_MEM_USE_HOST_PTR, n * out_bytes_, out + first * out_bytes_);
    cl::Event done = enqueue(in, result, n, {});
    slot_done[slot] = done;
    // Mapping makes the device's writes visible in the caller's array (no
    // copy where the device uses the host pointer itself).
    std::vector<cl::Event> after{done};
    Mapped map{result, nullptr, out + first * out_bytes_, n * out_bytes_, {}};
    map.pointer = queue.enqueueMapBuffer(result, CL_FALSE, CL_MAP_READ, 0, map.bytes, &after, &map.ready);
    maps.push_back(std::move(map));
    queue.flush();
  }
  std::vector<cl::Event> unmapped(maps.size());
  for (std::size_t i = 0; i < maps.size(); ++i) {
    maps[i].ready.wait();
    if (maps[i].pointer != maps[i].target) std::memcpy(maps[i].target, maps[i].pointer, maps[i].bytes);
    queue.enqueueUnmapMemObject(maps[i].buffer, maps[i].pointer, nullptr, &unmapped[i]);
  }
  cl::Event::waitForEvents(unmapped);
}

void HostBatches::run_copied(std::size_t batch, const Source& source, const Enqueue& enqueue, void* output) const {
  cl::CommandQueue& queue = device_.queue();
  struct Slot {
    cl::Buffer in, out;
    cl::Event uploaded, read_back;
  };
  const std::size_t slots = count_ > batch ? 2 : 1;
  // Several batches: uploads and read-backs go through a queue of their
  // own, so that the device may copy batch b + 1 in and batch b - 1 out
  // while it traces batch b (the events order each batch's three steps).
  cl::CommandQueue transfers = slots > 1 ? cl::CommandQueue(device_.context(), device_.device()) : queue;
  std::vector<Slot> slot(slots);
  for (Slot& s : slot) {
    s.in = device_.allocate(batch * in_bytes_, "query input batch", CL_MEM_READ_ONLY);
    s.out = device_.allocate(batch * out_bytes_, "query output batch", CL_MEM_WRITE_ONLY);
  }
  auto* out = static_cast<unsigned char*>(output);
  struct FinishOnError {  // no copy may still touch the caller's arrays after a throw
    cl::CommandQueue& queue;
    ~FinishOnError() {
      if (std::uncaught_exceptions() == 0) return;
      try {
        queue.finish();
      } catch (...) {  // the error in flight is the one to report
      }
    }
  } finish_transfers{transfers};
  std::size_t b = 0;
  for (std::size_t first = 0; first < count_; first += batch, ++b) {
    const std::size_t n = std::min(batch, count_ - first);
    const std::size_t k = b % slots;
    Slot& s = slot[k];
    // The slot's previous upload must be done before its staging is
    // refilled, and its previous read-back before its buffers are reused.
    if (s.uploaded()) s.uploaded.wait();
    const void* src = source(first, n, k);
    std::vector<cl::Event> before;
    if (s.read_back()) before.push_back(s.read_back);
    transfers.enqueueWriteBuffer(s.in, CL_FALSE, 0, n * in_bytes_, src, &before, &s.uploaded);
    transfers.flush();
    cl::Event traced = enqueue(s.in, s.out, n, {s.uploaded});
    queue.flush();
    std::vector<cl::Event> after{traced};
    transfers.enqueueReadBuffer(s.out, CL_FALSE, 0, n * out_bytes_, out + first * out_bytes_, &after, &s.read_back);
    transfers.flush();
  }
  for (Slot& s : slot)
    if (s.read_back()) s.read_back.wait();
}

void run_rays(const HostBatches& batches, const Rays& rays, std::vector<unsigned char>& staging,
              const HostBatches::Enqueue& enqueue, void* output) {
  if (rays.are_records()) {
    batches.run(rays.records().data(), enqueue, output);
    return;
  }
  batches.run([&](std::size_t first, std::size_t n, void* to) { rays.pack(first, std::span<Ray>(static_cast<Ray*>(to), n)); },
              staging, enqueue, output);
}

}  // namespace rtcl
