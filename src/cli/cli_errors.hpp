// The one error path of `rtcl`: every failure becomes one line
// "rtcl: error: <what>: <problem>" on stderr, <what> being the flag and its
// value, the argument, the file or the environment variable at fault (usage
// errors add a line pointing at --help), and an exit code from
// exit_codes.hpp. CLI11's own messages are rewritten into that form.
#pragma once

#include "exit_codes.hpp"
#include "rtcl/error.hpp"

namespace CLI {
class App;
}

namespace rtcl::cli {

// A bad command line found after CLI11 parsed it (an option value that
// the subcommand's own checks refuse, such as --device 99 or --frames 5:2):
// reported like CLI11's usage errors, exit 2.
class UsageError : public Error {
 public:
  using Error::Error;
};

// Runs `work`; an Error it throws becomes a UsageError with the same message
// (for checks of option values done by library calls).
template <class Work>
decltype(auto) as_usage_error(Work&& work) {
  try {
    return work();
  } catch (const UsageError&) {
    throw;
  } catch (const Error& e) {
    throw UsageError(e.what());
  }
}

// Parses argv into `app` and runs the chosen subcommand's callback. Returns
// the process exit code; --help and --version print to stdout and return
// ExitCode::ok; no subcommand at all is a usage error listing them.
int run_command_line(CLI::App& app, int argc, char** argv);

}  // namespace rtcl::cli
