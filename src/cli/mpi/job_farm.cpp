#include "mpi/job_farm.hpp"

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <deque>
#include <mutex>
#include <optional>
#include <thread>

#include "rtcl/error.hpp"

namespace rtcl::cli {

namespace {

enum Tag : int { tag_hello = 1, tag_job = 2, tag_result = 3, tag_failed = 4, tag_stop = 5 };

using Clock = std::chrono::steady_clock;

std::vector<std::byte> job_bytes(std::size_t job) {
  std::uint64_t j = job;
  std::vector<std::byte> out(sizeof j);
  std::memcpy(out.data(), &j, sizeof j);
  return out;
}

std::size_t job_of(std::span<const std::byte> bytes) {
  std::uint64_t j = 0;
  if (bytes.size() < sizeof j) throw Error("MPI: a job message of " + std::to_string(bytes.size()) + " bytes");
  std::memcpy(&j, bytes.data(), sizeof j);
  return static_cast<std::size_t>(j);
}

std::string describe(int rank, const RankOutcome& o, const std::string& host) {
  std::string text = "rank " + std::to_string(rank) + " (host " + host;
  if (o.report.is_object() && o.report.contains("device")) text += ", device " + o.report["device"].get<std::string>();
  return text + ")";
}

// Rank 0's own worker: a thread taking jobs from the shared queue. It never
// calls MPI (MPI_THREAD_FUNNELED).
class LocalWorker {
 public:
  LocalWorker(std::deque<std::size_t>& pending, std::mutex& mutex, std::condition_variable& wake,
              const JobSetup& setup, const JobRun& run)
      : pending_(pending), mutex_(mutex), wake_(wake), thread_([this, &setup, &run] { loop(setup, run); }) {}
  ~LocalWorker() { join(); }

  // Stops taking jobs and waits for the thread (its setup, or the job it
  // runs, finishes first).
  void join() {
    if (!thread_.joinable()) return;
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }

  struct Done {
    std::size_t job;
    std::vector<std::byte> bytes;
    Clock::time_point start;
    double ms;
  };
  // Under the mutex: finished jobs, the setup report, a failure.
  std::deque<Done> done;
  std::optional<nlohmann::json> report;
  std::optional<std::pair<long long, std::string>> failure;  // job (-1: setup), message
  bool alive = true;

 private:
  void loop(const JobSetup& setup, const JobRun& run) {
    try {
      nlohmann::json r = setup();
      std::lock_guard lock(mutex_);
      report = std::move(r);
    } catch (const std::exception& e) {
      std::lock_guard lock(mutex_);
      failure = {-1, e.what()};
      return;
    }
    for (;;) {
      std::size_t job;
      {
        std::unique_lock lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || !pending_.empty(); });
        if (stop_) return;
        job = pending_.front();
        pending_.pop_front();
      }
      Clock::time_point start = Clock::now();
      try {
        std::vector<std::byte> bytes = run(job);
        double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
        std::lock_guard lock(mutex_);
        done.push_back({job, std::move(bytes), start, ms});
      } catch (const std::exception& e) {
        std::lock_guard lock(mutex_);
        failure = {static_cast<long long>(job), e.what()};
        return;
      }
    }
  }

  std::deque<std::size_t>& pending_;
  std::mutex& mutex_;
  std::condition_variable& wake_;
  bool stop_ = false;
  std::thread thread_;
};

// Jobs out at once per remote rank: the next job waits in the rank's
// message queue while it renders the current one, so a rank does not sit
// idle for the round trip through rank 0 between two jobs.
constexpr std::size_t jobs_ahead = 2;

// Adds the time from `start` to its end to `ms`.
class ServeTimer {
 public:
  ServeTimer(double& ms, Clock::time_point start) : ms_(ms), start_(start) {}
  ~ServeTimer() { ms_ += std::chrono::duration<double, std::milli>(Clock::now() - start_).count(); }

 private:
  double& ms_;
  Clock::time_point start_;
};

enum class State { starting, working, failed, stopped };

struct Remote {
  State state = State::starting;
  std::deque<std::size_t> jobs;  // handed out, results not yet in (a rank returns them in order)
  Clock::time_point since;       // the oldest job's hand-out, or the last result
};

}  // namespace

std::vector<RankOutcome> serve_jobs(const MpiWorld& world, const std::vector<std::size_t>& order,
                                    const JobSetup& setup, const JobRun& run, const JobResult& on_result,
                                    FarmTimes* times) {
  std::optional<Clock::time_point> first_out;
  Clock::time_point last_in = Clock::now();
  double serve_ms = 0.0;
  std::size_t remote_results = 0;
  std::vector<RankOutcome> outcomes(world.size);
  std::vector<Remote> remotes(world.size);
  std::vector<std::string> hosts(world.size, "?");
  hosts[0] = world.host;
  std::deque<std::size_t> pending(order.begin(), order.end());
  std::mutex mutex;
  std::condition_variable wake;
  std::size_t done = 0;
  const std::size_t total = order.size();

  auto fail = [&](int rank, long long job, const std::string& message) {
    RankOutcome& o = outcomes[rank];
    o.failure = message;
    std::fprintf(stderr, "rtcl: warning: %s failed%s: %s%s\n", describe(rank, o, hosts[rank]).c_str(),
                 job < 0 ? " while setting up" : (" on job " + std::to_string(job)).c_str(), message.c_str(),
                 job < 0 ? "" : "; the job goes to another rank");
    std::lock_guard lock(mutex);
    if (job >= 0 && (rank == 0 || remotes[rank].jobs.empty())) pending.push_front(static_cast<std::size_t>(job));
    if (rank > 0) {  // the failed job and those queued behind it
      for (auto j = remotes[rank].jobs.rbegin(); j != remotes[rank].jobs.rend(); ++j) pending.push_front(*j);
      remotes[rank].jobs.clear();
    }
  };

  {
    LocalWorker local(pending, mutex, wake, setup, run);
    auto stop_remotes = [&] {
      for (int r = 1; r < world.size; ++r) {
        // A starting rank's hello or failure is on its way, a working
        // one's results (dropped: only an error ends the run with jobs out).
        while (remotes[r].state == State::starting ||
               (remotes[r].state == State::working && !remotes[r].jobs.empty())) {
          Message m = wait_message(r);
          if (m.tag == tag_hello) {
            outcomes[r].report = nlohmann::json::parse(as_text(m.bytes));
            remotes[r].state = State::working;
          } else if (m.tag == tag_result) {
            remotes[r].jobs.pop_front();
          } else if (m.tag == tag_failed) {
            remotes[r].state = State::failed;
            outcomes[r].failure = nlohmann::json::parse(as_text(m.bytes)).value("message", std::string("?"));
          }
        }
        if (remotes[r].state == State::working) {
          send_bytes(r, tag_stop, {});
          remotes[r].state = State::stopped;
        }
      }
    };
    try {
      while (done < total) {
        bool progressed = false;
        {
          std::unique_lock lock(mutex);
          while (!local.done.empty()) {
            LocalWorker::Done d = std::move(local.done.front());
            local.done.pop_front();
            lock.unlock();
            on_result(0, d.job, d.bytes);
            if (!first_out || d.start < *first_out) first_out = d.start;
            last_in = Clock::now();
            outcomes[0].jobs++;
            outcomes[0].busy_ms += d.ms;
            ++done;
            progressed = true;
            lock.lock();
          }
          if (local.report && outcomes[0].report.is_null()) {
            outcomes[0].report = *local.report;
            outcomes[0].report["host"] = world.host;
          }
          if (local.failure && local.alive) {
            local.alive = false;
            auto [job, message] = *local.failure;
            lock.unlock();
            fail(0, job, message);
            progressed = true;
          }
        }
        for (;;) {
          Clock::time_point serve_start = Clock::now();
          std::optional<Message> m = poll_message();
          if (!m) break;
          ServeTimer timer(serve_ms, serve_start);
          progressed = true;
          int r = m->source;
          if (r <= 0 || r >= world.size) continue;
          if (m->tag == tag_hello) {
            outcomes[r].report = nlohmann::json::parse(as_text(m->bytes));
            if (outcomes[r].report.contains("host")) hosts[r] = outcomes[r].report["host"].get<std::string>();
            remotes[r].state = State::working;
          } else if (m->tag == tag_result) {
            std::size_t job = job_of(m->bytes);
            if (remotes[r].jobs.empty() || remotes[r].jobs.front() != job)
              throw Error("MPI: rank " + std::to_string(r) + " returned job " + std::to_string(job) +
                          ", which it was not working on");
            remotes[r].jobs.pop_front();
            on_result(r, job, std::span(m->bytes).subspan(8));
            last_in = Clock::now();
            outcomes[r].jobs++;
            outcomes[r].busy_ms += std::chrono::duration<double, std::milli>(last_in - remotes[r].since).count();
            remotes[r].since = last_in;
            ++done;
            ++remote_results;
          } else if (m->tag == tag_failed) {
            nlohmann::json f = nlohmann::json::parse(as_text(m->bytes));
            if (f.contains("host")) hosts[r] = f["host"].get<std::string>();
            remotes[r].state = State::failed;
            fail(r, f.value("job", -1LL), f.value("message", std::string("unknown failure")));
          }
        }
        for (std::size_t round = 0; round < jobs_ahead; ++round)  // one job to each rank before a second
          for (int r = 1; r < world.size; ++r) {
            if (remotes[r].state != State::working || remotes[r].jobs.size() > round) continue;
            std::size_t job;
            {
              std::lock_guard lock(mutex);
              if (pending.empty()) break;
              job = pending.front();
              pending.pop_front();
            }
            Clock::time_point now = Clock::now();
            ServeTimer timer(serve_ms, now);
            if (remotes[r].jobs.empty()) remotes[r].since = now;
            remotes[r].jobs.push_back(job);
            if (!first_out || now < *first_out) first_out = now;
            send_bytes(r, tag_job, job_bytes(job));
          }
        bool queued;
        {
          std::lock_guard lock(mutex);
          queued = !pending.empty();
        }
        if (queued) wake.notify_one();
        bool anyone = local.alive;
        for (int r = 1; r < world.size; ++r)
          anyone = anyone || remotes[r].state == State::starting || remotes[r].state == State::working;
        if (!anyone) {
          throw Error("every rank failed (the warnings above say how), with " + std::to_string(total - done) +
                      " of " + std::to_string(total) + " jobs left; nothing was written");
        }
        if (!progressed) std::this_thread::sleep_for(std::chrono::microseconds(100));
      }
    } catch (...) {
      stop_remotes();
      throw;
    }
    stop_remotes();
    // Rank 0's setup may end after the last job: its report still counts.
    local.join();
    if (outcomes[0].report.is_null() && local.report) {
      outcomes[0].report = *local.report;
      outcomes[0].report["host"] = world.host;
    }
    if (local.failure && outcomes[0].failure.empty()) outcomes[0].failure = local.failure->second;
  }
  if (times && first_out) {
    times->span_ms = std::chrono::duration<double, std::milli>(last_in - *first_out).count();
    times->serve_ms = serve_ms;
    times->remote_results = remote_results;
  }
  return outcomes;
}

bool work_jobs(const MpiWorld& world, const JobSetup& setup, const JobRun& run) {
  auto report_failure = [&](long long job, const std::string& message) {
    nlohmann::json f{{"job", job}, {"host", world.host}, {"message", message}};
    send_bytes(0, tag_failed, as_bytes(f.dump()));
  };
  try {
    nlohmann::json report = setup();
    report["host"] = world.host;
    send_bytes(0, tag_hello, as_bytes(report.dump()));
  } catch (const std::exception& e) {
    report_failure(-1, e.what());
    return false;
  }
  for (;;) {
    Message m = wait_message(0);
    if (m.tag == tag_stop) return true;
    if (m.tag != tag_job) continue;
    std::size_t job = job_of(m.bytes);
    std::vector<std::byte> out = job_bytes(job);
    try {
      std::vector<std::byte> result = run(job);
      out.insert(out.end(), result.begin(), result.end());
    } catch (const std::exception& e) {
      report_failure(static_cast<long long>(job), e.what());
      return false;
    }
    send_bytes(0, tag_result, out);
  }
}

}  // namespace rtcl::cli
