#include "rtcl/thread_pool.hpp"

#include <pthread.h>


#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <new>
#include <thread>
#include <vector>

namespace rtcl {

namespace {

// One run_jobs call: its jobs 1 .. count - 1 wait in the pool's queue until
// a thread claims them. Lives on the caller's stack; guarded by the pool's
// mutex.
struct Batch {
  const std::function<void(unsigned)>* job;
  unsigned count;
  unsigned next;                  // the next job to claim
  std::atomic<unsigned> running;  // jobs not yet returned, job 0 included (changed under the mutex)
  std::vector<std::exception_ptr> errors;
  std::condition_variable finished;
};

class ThreadPool;
ThreadPool* the_pool = nullptr;  // for the fork handlers
// Jobs the calling thread is running (nested run_jobs calls count once in
// ThreadPool::active_).
thread_local unsigned jobs_on_this_thread = 0;

class ThreadPool {
 public:
  // A fork while a pool thread holds the mutex, or waits on work_, would
  // leave the child a locked mutex or a condition variable with waiters
  // that do not exist there (the child has only the forking thread): the
  // mutex is held across the fork, and the child starts with a fresh
  // condition variable and no threads.
  ThreadPool() {
    the_pool = this;
    pthread_atfork([] { the_pool->mutex_.lock(); }, [] { the_pool->mutex_.unlock(); },
                   [] {
                     new (&the_pool->work_) std::condition_variable;
                     the_pool->forget_threads();
                     the_pool->mutex_.unlock();
                   });
  }
  ~ThreadPool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    work_.notify_all();
    for (std::thread& t : threads_) t.join();
  }

  void run(unsigned jobs, const std::function<void(unsigned)>& job) {
    Batch batch{&job, jobs, 1, jobs, std::vector<std::exception_ptr>(jobs), {}};
    {
      std::lock_guard<std::mutex> lock(mutex_);
      queue_.push_back(&batch);
      unclaimed_ += jobs - 1;
      unclaimed_now_.store(unclaimed_, std::memory_order_relaxed);
      // every waiting job has an idle thread to take it at once
      while (idle_ < unclaimed_) {
        ++idle_;
        threads_.emplace_back([this] { serve(); });
      }
    }
    if (jobs > 2)
      work_.notify_all();
    else
      work_.notify_one();
    const bool outermost = jobs_on_this_thread == 0;
    if (outermost) active_.fetch_add(1, std::memory_order_relaxed);
    ++jobs_on_this_thread;
    execute(batch, 0);
    spin_until([&] { return batch.running.load(std::memory_order_relaxed) == 0; });
    --jobs_on_this_thread;
    if (outermost) active_.fetch_sub(1, std::memory_order_relaxed);
    // the mutex, taken after the last job's release of it, before the batch
    // goes out of scope
    std::unique_lock<std::mutex> lock(mutex_);
    batch.finished.wait(lock, [&] { return batch.running == 0; });
    lock.unlock();
    for (const std::exception_ptr& e : batch.errors)
      if (e) std::rethrow_exception(e);
  }

 private:
  void execute(Batch& batch, unsigned k) {
    try {
      (*batch.job)(k);
    } catch (...) {
      batch.errors[k] = std::current_exception();
    }
    // the batch is not touched once its caller has seen running == 0
    std::lock_guard<std::mutex> lock(mutex_);
    if (--batch.running == 0) batch.finished.notify_one();
  }

  // A pool thread: runs the oldest waiting job until the pool stops.
  void serve() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      if (!stopping_ && queue_.empty()) {
        lock.unlock();
        if (active_.fetch_add(1, std::memory_order_relaxed) < cores_)
          spin_until([&] { return unclaimed_now_.load(std::memory_order_relaxed) > 0; });
        active_.fetch_sub(1, std::memory_order_relaxed);
        lock.lock();
      }
      work_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;
      Batch& batch = *queue_.front();
      const unsigned k = batch.next++;
      if (batch.next == batch.count) queue_.pop_front();
      --unclaimed_;
      unclaimed_now_.store(unclaimed_, std::memory_order_relaxed);
      --idle_;
      lock.unlock();
      active_.fetch_add(1, std::memory_order_relaxed);
      jobs_on_this_thread = 1;
      execute(batch, k);
      jobs_on_this_thread = 0;
      active_.fetch_sub(1, std::memory_order_relaxed);
      lock.lock();
      ++idle_;
    }
  }

  // In a forked child (the threads' handles copied, the threads themselves
  // not): the pool starts anew, the handles let go.
  void forget_threads() {
    for (std::thread& t : threads_) t.detach();
    threads_.clear();
    queue_.clear();
    unclaimed_ = idle_ = 0;
    unclaimed_now_.store(0, std::memory_order_relaxed);
    active_.store(0, std::memory_order_relaxed);
  }

  std::mutex mutex_;
  std::condition_variable work_;  // a job is waiting, or the pool stops
  std::deque<Batch*> queue_;      // batches with unclaimed jobs, oldest first
  unsigned unclaimed_ = 0;        // jobs in queue_'s batches not yet claimed
  std::atomic<unsigned> unclaimed_now_{0};  // unclaimed_, for spinning threads (written under the mutex)
  // Threads running jobs (callers and pool threads) or spinning for one: a
  // pool thread spins only while fewer than cores_ are (a spinning thread
  // must not take a core from one with work). Signed: a fork inside a job
  // starts the child at 0.
  std::atomic<int> active_{0};
  const int cores_ = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  unsigned idle_ = 0;             // pool threads not running a job
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace

void run_jobs(unsigned jobs, const std::function<void(unsigned)>& job) {
  if (jobs == 0) return;
  if (jobs == 1) {
    job(0);
    return;
  }
  static ThreadPool pool;
  pool.run(jobs, job);
}

}  // namespace rtcl
