// Dynamic load balancing over MPI ranks: rank 0 hands out numbered jobs
// (image tiles, benchmark cells) one at a time to whichever rank asks, and
// renders jobs itself in a second thread while its main thread serves.
//
// Protocol (every message a byte string):
//   worker -> 0  hello   its setup report (JSON text), after its setup
//   0 -> worker  job     the job number (8 bytes)
//   worker -> 0  result  the job number (8 bytes) then the job's bytes
// Rank 0 keeps two jobs out per rank (the second waits in the rank's queue
// while it runs the first), so no rank idles for a round trip between jobs.
//   worker -> 0  failed  JSON {job (-1: during setup), host, message}
//   0 -> worker  stop    no more jobs
// A worker whose setup or job throws sends `failed` and takes no more jobs;
// its jobs go back to the front of the queue for the other ranks. A rank
// that asks while the queue is empty but jobs are still out waits, so that
// it can take a failed rank's job. The run fails (Error, no result) only
// when every rank has failed with jobs left. A rank that dies without a
// word (killed) is not detected here: under Open MPI's mpirun the whole
// job then ends (docs/cli.md, "Under mpirun").
#pragma once

#include <cstddef>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mpi/mpi_world.hpp"

namespace rtcl::cli {

// Builds what the jobs need (device, structure) and reports it, e.g.
// {"device": ..., "build_ms": ...}; throws on failure.
using JobSetup = std::function<nlohmann::json()>;
// Runs one job and returns its result bytes; throws on failure.
using JobRun = std::function<std::vector<std::byte>(std::size_t job)>;
// On rank 0, in its main thread: one job's result from `rank`.
using JobResult = std::function<void(int rank, std::size_t job, std::span<const std::byte> bytes)>;

struct FarmTimes {
  // From the first job handed out (to any rank, rank 0's thread included)
  // to the last result in, in ms: the distributed work without the ranks'
  // setup before their first job.
  double span_ms = 0.0;
  // Rank 0's main thread receiving and handling remote results (on_result
  // included) and handing out jobs, in ms: its serial share of the work,
  // which bounds how many ranks it can serve.
  double serve_ms = 0.0;
  std::size_t remote_results = 0;
};

struct RankOutcome {
  nlohmann::json report;  // the setup report, with "host" added; null when setup failed
  std::size_t jobs = 0;   // jobs this rank returned
  std::string failure;    // "" or what failed, as the rank reported it
  // Rank 0's view, summed over the rank's results: from the later of the
  // job's hand-out and the previous result to this result.
  double busy_ms = 0.0;
};

// Rank 0: every job of `order` (job numbers, in the order to hand them
// out) done once, by some rank; returns one outcome per rank. Prints a
// warning naming rank, host and job for each failure. Throws Error when
// jobs are left and no rank can take them.
std::vector<RankOutcome> serve_jobs(const MpiWorld& world, const std::vector<std::size_t>& order,
                                    const JobSetup& setup, const JobRun& run, const JobResult& on_result,
                                    FarmTimes* times = nullptr);

// Ranks > 0: setup, then jobs until rank 0 says stop. False when this rank
// failed (and told rank 0 so).
bool work_jobs(const MpiWorld& world, const JobSetup& setup, const JobRun& run);

}  // namespace rtcl::cli
