// run_jobs (thread_pool.hpp): every job on a thread of its own at the same
// time (jobs that wait for each other finish), nested calls, the lowest
// job's exception, and a pool used again in a forked child; the loops and
// reserve_faulted of parallel.hpp.
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <condition_variable>
#include <csignal>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "rtcl/parallel.hpp"
#include "rtcl/thread_pool.hpp"

namespace {

using namespace std::chrono_literals;

// Waits until `count` threads have arrived; false after 10 s (jobs that do
// not run at the same time never all arrive).
class Rendezvous {
 public:
  explicit Rendezvous(unsigned count) : count_(count) {}
  bool arrive() {
    std::unique_lock<std::mutex> lock(mutex_);
    if (++arrived_ == count_) all_.notify_all();
    return all_.wait_for(lock, 10s, [&] { return arrived_ >= count_; });
  }

 private:
  std::mutex mutex_;
  std::condition_variable all_;
  unsigned count_, arrived_ = 0;
};

TEST(ThreadPool, JobsRunAtTheSameTimeOnDistinctThreads) {
  for (unsigned jobs : {2u, 3u, 8u})
    for (int repeat = 0; repeat < 3; ++repeat) {
      Rendezvous all(jobs);
      std::vector<std::thread::id> ids(jobs);
      std::atomic<unsigned> met{0};
      rtcl::run_jobs(jobs, [&](unsigned k) {
        ids[k] = std::this_thread::get_id();
        met += all.arrive();
      });
      EXPECT_EQ(met, jobs) << jobs << " jobs";
      EXPECT_EQ(ids[0], std::this_thread::get_id()) << "job 0 runs on the caller";
      std::sort(ids.begin(), ids.end());
      EXPECT_EQ(std::unique(ids.begin(), ids.end()), ids.end()) << jobs << " jobs share a thread";
    }
}

TEST(ThreadPool, NestedCallsRunAtTheSameTimeAsTheirParents) {
  // two outer jobs, each running two inner jobs (itself one of them): four
  // threads at one rendezvous
  Rendezvous all(4);
  std::atomic<unsigned> met{0};
  rtcl::run_jobs(2, [&](unsigned) { rtcl::run_jobs(2, [&](unsigned) { met += all.arrive(); }); });
  EXPECT_EQ(met, 4u);
}

TEST(ThreadPool, RethrowsTheLowestFailingJobAfterAllReturned) {
  std::atomic<unsigned> returned{0};
  try {
    rtcl::run_jobs(4, [&](unsigned k) {
      ++returned;
      if (k == 3) throw std::runtime_error("job 3");
      if (k == 1) {
        std::this_thread::sleep_for(20ms);
        throw std::runtime_error("job 1");
      }
    });
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "job 1");
  }
  EXPECT_EQ(returned, 4u);
}

TEST(ThreadPool, ForEachIndexVisitsEveryIndexOnce) {
  std::vector<std::atomic<int>> visits(1000);
  rtcl::for_each_index(visits.size(), 3, [&](std::size_t k) { ++visits[k]; });
  for (std::size_t k = 0; k < visits.size(); ++k) ASSERT_EQ(visits[k], 1) << k;
}

// reserve_faulted keeps the elements there are and makes room for n more
// (its page writes fall in the room only), from a vector that is empty
// and from one that is not.
TEST(ThreadPool, ReserveFaultedKeepsTheElementsAndMakesRoom) {
  std::vector<std::uint32_t> empty;
  rtcl::reserve_faulted(empty, 3'000'000, 2);
  EXPECT_TRUE(empty.empty());
  EXPECT_GE(empty.capacity(), 3'000'000u);
  std::vector<std::uint32_t> some = {7, 8, 9};
  rtcl::reserve_faulted(some, 3'000'000, 2);
  EXPECT_EQ(some, (std::vector<std::uint32_t>{7, 8, 9}));
  EXPECT_GE(some.capacity(), 3'000'000u);
  some.resize(3'000'000);
  EXPECT_EQ(some[2], 9u);
  EXPECT_EQ(some[3], 0u);
  EXPECT_EQ(some.back(), 0u);
}

// Forked right after a call returns, while the parent's pool threads may
// still hold the pool's lock or wait on its condition variable (before the
// pool's fork handlers, six runs of this test in six hung a child, in
// rounds 0 to 44): 50 times.
TEST(ThreadPool, AForkedChildRunsJobsOnThreadsOfItsOwn) {
  for (int round = 0; round < 50; ++round) {
    rtcl::run_jobs(3, [](unsigned) {});  // the parent's pool has threads
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      alarm(20);  // a child whose jobs never run is killed, not left hanging
      Rendezvous all(3);
      std::atomic<unsigned> met{0};
      rtcl::run_jobs(3, [&](unsigned) { met += all.arrive(); });
      _exit(met == 3 ? 0 : 1);
    }
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status)) << "round " << round << ": the child was killed by signal " << WTERMSIG(status);
    ASSERT_EQ(WEXITSTATUS(status), 0) << "round " << round;
  }
}

}  // namespace
