#include "scratch.hpp"

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>

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

namespace {

// The other host thread of one pipeline() call: runs one posted task at a
// time and sleeps between tasks. (A thread of the library's pool would spin
// for its next job while the device works, and on a CPU device take a core
// from the device's own threads.)
class Helper {
 public:
  Helper() : thread_([this] { serve(); }) {}
  ~Helper() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  Helper(const Helper&) = delete;
  Helper& operator=(const Helper&) = delete;

  void post(std::function<void()> task) {
    {
      std::lock_guard lock(mutex_);
      task_ = std::move(task);
      pending_ = true;
    }
    changed_.notify_all();
  }
  // Waits for the posted task; returns its exception, if any.
  std::exception_ptr wait() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return !pending_; });
    return std::exchange(error_, nullptr);
  }

 private:
  void serve() {
    std::unique_lock lock(mutex_);
    for (;;) {
      changed_.wait(lock, [&] { return pending_ || stopping_; });
      if (!pending_) return;
      std::function<void()> task = std::move(task_);
      lock.unlock();
      std::exception_ptr error;
      try {
        task();
      } catch (...) {
        error = std::current_exception();
      }
      lock.lock();
      error_ = error;
      pending_ = false;
      changed_.notify_all();
    }
  }

  std::mutex mutex_;
  std::condition_variable changed_;
  std::function<void()> task_;
  bool pending_ = false, stopping_ = false;
  std::exception_ptr error_;
  std::thread thread_;  // last: starts when the rest is ready
};

// Where pipeline() splits [0, count): the chunks' bounds, 0 first and count
// last (pipeline's comment in scratch.hpp).
std::vector<std::size_t> chunk_bounds(std::size_t count) {
  std::vector<std::size_t> front{0}, back{count};
  // The ramps: each chunk at most kRampFactor times its neighbour, so that
  // the helper's conversions of a neighbour end before the device ends this
  // chunk's work. A pair of ramp chunks is taken while at least one more of
  // its size is left for between them (below 3 kEdgeChunk: one chunk).
  std::size_t left = count, size = kEdgeChunk, last = 0;
  for (; size <= kChunk && left >= 3 * size; size *= kRampFactor) {
    front.push_back(front.back() + size);
    back.push_back(back.back() - size);
    left -= 2 * size;
    last = size;
  }
  // Between the ramps: equal chunks of at most kChunk; a remainder smaller
  // than the ramps' largest chunk joins the first ramp's last chunk instead.
  if (left < last) {
    front.back() += left;
    left = 0;
  }
  const std::size_t middle = (left + kChunk - 1) / kChunk;
  const std::size_t start = front.back();
  for (std::size_t k = 1; k < middle; ++k) front.push_back(start + left * k / middle);
  front.insert(front.end(), back.rbegin(), back.rend());
  return front;
}

}  // namespace

void pipeline(std::size_t count, const std::function<void(int, std::size_t, std::size_t, bool)>& pack,
              const std::function<void(int, std::size_t, std::size_t)>& run,
              const std::function<void(int, std::size_t, std::size_t, bool)>& unpack) {
  if (count == 0) return;
  const std::vector<std::size_t> bounds = chunk_bounds(count);
  const std::size_t chunks = bounds.size() - 1;
  auto first = [&](std::size_t k) { return bounds[k]; };
  auto size = [&](std::size_t k) { return bounds[k + 1] - bounds[k]; };
  pack(0, 0, size(0), true);
  if (chunks == 1) {
    run(0, 0, size(0));
  } else {
    Helper helper;
    for (std::size_t k = 0; k < chunks; ++k) {
      const int slot = static_cast<int>(k % 2), other = 1 - slot;
      helper.post([&, k, other] {
        if (k > 0) unpack(other, first(k - 1), size(k - 1), false);
        if (k + 1 < chunks) pack(other, first(k + 1), size(k + 1), false);
      });
      std::exception_ptr run_error;
      try {
        run(slot, first(k), size(k));
      } catch (...) {
        run_error = std::current_exception();
      }
      const std::exception_ptr help_error = helper.wait();
      if (run_error) std::rethrow_exception(run_error);
      if (help_error) std::rethrow_exception(help_error);
    }
  }
  unpack(static_cast<int>((chunks - 1) % 2), first(chunks - 1), size(chunks - 1), true);
}

}  // namespace rtcl::python
