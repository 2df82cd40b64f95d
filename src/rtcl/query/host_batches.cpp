#include "rtcl/query/host_batches.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>
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
                         std::size_t out_item_bytes, std::size_t max_batch_items)
    : device_(device),
      count_(count),
      in_bytes_(in_item_bytes),
      out_bytes_(out_item_bytes),
      shared_memory_(device.info().type == "cpu" && !copy_forced()) {
  const std::size_t largest = std::max(in_item_bytes, out_item_bytes);
  std::size_t fit = device.info().max_alloc_bytes / largest;
  if (fit == 0)
    throw Error("device " + device.info().name + " allows buffers of " + std::to_string(device.info().max_alloc_bytes) +
                " bytes, fewer than one query record of " + std::to_string(largest));
  batch_items_ = std::min(fit, max_batch_items ? max_batch_items : fit);
  batch_items_ = std::max<std::size_t>(1, std::min(batch_items_, count));
}

void HostBatches::run(const Input& input, const Enqueue& enqueue, void* output) const {
  if (count_ == 0) return;
  with_cl_errors([&] {
    try {
      if (shared_memory_)
        run_shared(input, enqueue, output);
      else
        run_copied(input, enqueue, output);
    } catch (...) {
      device_.queue().finish();  // no command may still write into the caller's arrays
      throw;
    }
  });
}

void HostBatches::run_shared(const Input& input, const Enqueue& enqueue, void* output) const {
  const cl::Context& context = device_.context();
  cl::CommandQueue& queue = device_.queue();
  std::vector<unsigned char> staging;
  auto* out = static_cast<unsigned char*>(output);
  for (std::size_t first = 0; first < count_; first += batch_items_) {
    const std::size_t n = std::min(batch_items_, count_ - first);
    if (staging.empty()) staging.resize(batch_items_ * in_bytes_);
    const void* src = input(first, n, staging.data());
    cl::Buffer in(context, CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR, n * in_bytes_, const_cast<void*>(src));
    cl::Buffer result(context, CL_MEM_WRITE_ONLY | CL_MEM_USE_HOST_PTR, n * out_bytes_, out + first * out_bytes_);
    cl::Event done = enqueue(in, result, n, {});
    // Mapping makes the device's writes visible in the caller's array (no
    // copy where the device uses the host pointer itself).
    std::vector<cl::Event> after{done};
    void* mapped = queue.enqueueMapBuffer(result, CL_TRUE, CL_MAP_READ, 0, n * out_bytes_, &after);
    if (mapped != out + first * out_bytes_) std::memcpy(out + first * out_bytes_, mapped, n * out_bytes_);
    cl::Event unmapped;
    queue.enqueueUnmapMemObject(result, mapped, nullptr, &unmapped);
    unmapped.wait();
  }
}

void HostBatches::run_copied(const Input& input, const Enqueue& enqueue, void* output) const {
  cl::CommandQueue& queue = device_.queue();
  struct Slot {
    cl::Buffer in, out;
    std::vector<unsigned char> staging;
    cl::Event uploaded, read_back;
  };
  const std::size_t slots = count_ > batch_items_ ? 2 : 1;
  std::vector<Slot> slot(slots);
  for (Slot& s : slot) {
    s.in = device_.allocate(batch_items_ * in_bytes_, "query input batch", CL_MEM_READ_ONLY);
    s.out = device_.allocate(batch_items_ * out_bytes_, "query output batch", CL_MEM_WRITE_ONLY);
  }
  auto* out = static_cast<unsigned char*>(output);
  std::size_t b = 0;
  for (std::size_t first = 0; first < count_; first += batch_items_, ++b) {
    const std::size_t n = std::min(batch_items_, count_ - first);
    Slot& s = slot[b % slots];
    // The slot's previous upload must be done before its staging is
    // refilled, and its previous read-back before its buffers are reused
    // (the in-order queue orders the rest).
    if (s.uploaded()) s.uploaded.wait();
    if (s.staging.empty()) s.staging.resize(batch_items_ * in_bytes_);
    const void* src = input(first, n, s.staging.data());
    std::vector<cl::Event> before;
    if (s.read_back()) before.push_back(s.read_back);
    queue.enqueueWriteBuffer(s.in, CL_FALSE, 0, n * in_bytes_, src, &before, &s.uploaded);
    cl::Event traced = enqueue(s.in, s.out, n, {s.uploaded});
    std::vector<cl::Event> after{traced};
    queue.enqueueReadBuffer(s.out, CL_FALSE, 0, n * out_bytes_, out + first * out_bytes_, &after, &s.read_back);
    queue.flush();
  }
  for (Slot& s : slot)
    if (s.read_back()) s.read_back.wait();
}

}  // namespace rtcl
