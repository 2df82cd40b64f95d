// Runs the built `rtcl` binary as a subprocess in a test's temporary
// directory and captures its exit code and output; expectations shared by
// the tests of failing runs.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "support/temp_dir.hpp"

namespace rtcl::test {

struct CliRun {
  // exit code; -1 when the process did not exit normally (a crash), -2: no
  // binary, -3: no process; 124: killed after 120 s (a hang)
  int status = -1;
  std::string out, err;
  double seconds = 0.0;      // wall-clock time of the run
  double max_rss_mib = 0.0;  // peak resident memory of the run (the largest of its processes)
};

std::string shell_quoted(const std::string& s);

// Runs `rtcl args...` in dir. `env` is prepended as shell assignments
// ("NAME=value ...", already quoted); `limits` as shell commands before it
// (e.g. "ulimit -v 1048576;").
CliRun run_cli(const TempDir& dir, const std::vector<std::string>& args, const std::string& env = "",
               const std::string& limits = "");

// Like run_cli, with `launcher` (e.g. "mpirun -np 2", already quoted) in
// front of the rtcl binary.
CliRun run_cli_launched(const TempDir& dir, const std::string& launcher, const std::vector<std::string>& args,
                        const std::string& env = "");

// The environment of MPI ranks started by a test: `extra`, and under
// AddressSanitizer (scripts/test.sh --sanitize) leak checking off for them
// (Open MPI 4.1 leaks from components it unloads at MPI_Finalize, so
// LeakSanitizer's reports carry no library name to suppress them by: a
// two-rank MPI_Bcast program built with -fsanitize=address aborts at exit)
// and no alternate signal stacks (with them, a rank's exiting Open MPI
// thread fails in AddressSanitizer's own unmapping of its signal stack,
// "failed to deallocate ... unable to unmap", before any test code runs).
// Memory errors are still caught.
std::string mpi_rank_env(const std::string& extra = "");

std::size_t count_of(const std::string& text, const std::string& fragment);

// A failed run: exit `status` (1: bad input, 2: usage), exactly one
// "rtcl: error:" line containing `fragment`, no output file `output` (when
// given) and no temporary file left in dir.
void expect_failure(const CliRun& run, const std::string& fragment, const TempDir& dir,
                    const std::string& output = "", int status = 1);

// A usage error: exit 2, one "rtcl: error:" line containing `fragment`, and
// a pointer to --help.
void expect_usage_error(const CliRun& run, const std::string& fragment);

}  // namespace rtcl::test
