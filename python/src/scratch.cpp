#include "scratch.hpp"

#include <algorithm>
#include <mutex>

#include "rtcl/thread_pool.hpp"

namespace rtcl::python {

namespace {

// Never destroyed (like the devices): a pool emptied at exit would only
// return memory the process is about to give back.
struct Pool {
  std::mutex mutex;
  std::vector<std::unique_ptr<Scratch>> free;
};
Pool& pool() {
  static auto* p = new Pool();
  return *p;
}

}  // namespace

ScratchLease::ScratchLease() {
  Pool& p = pool();
  std::lock_guard lock(p.mutex);
  if (p.free.empty()) {
    scratch_ = std::make_unique<Scratch>();
  } else {
    scratch_ = std::move(p.free.back());
    p.free.pop_back();
  }
}

ScratchLease::~ScratchLease() {
  Pool& p = pool();
  std::lock_guard lock(p.mutex);
  p.free.push_back(std::move(scratch_));
}

void pipeline(std::size_t count, const std::function<void(int, std::size_t, std::size_t, bool)>& pack,
              const std::function<void(int, std::size_t, std::size_t)>& run,
              const std::function<void(int, std::size_t, std::size_t, bool)>& unpack) {
  if (count == 0) return;
  const std::size_t chunks = (count + kChunk - 1) / kChunk;
  auto first = [](std::size_t k) { return k * kChunk; };
  auto size = [&](std::size_t k) { return std::min(kChunk, count - k * kChunk); };
  pack(0, 0, size(0), true);
  for (std::size_t k = 0; k < chunks; ++k) {
    const int slot = static_cast<int>(k % 2), other = 1 - slot;
    if (chunks == 1) {
      run(slot, first(k), size(k));
      break;
    }
    run_jobs(2, [&](unsigned job) {
      if (job == 0) {
        run(slot, first(k), size(k));
        return;
      }
      if (k > 0) unpack(other, first(k - 1), size(k - 1), false);
      if (k + 1 < chunks) pack(other, first(k + 1), size(k + 1), false);
    });
  }
  unpack(static_cast<int>((chunks - 1) % 2), first(chunks - 1), size(chunks - 1), true);
}

}  // namespace rtcl::python
