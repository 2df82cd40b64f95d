// The one error path of `rtcl`: every failure becomes one line
// "rtcl: error: <input>: <problem>" on stderr (usage errors add a line
// pointing at --help) and an exit code from exit_codes.hpp.
#pragma once

#include "exit_codes.hpp"
#include "rtcl/error.hpp"

namespace CLI {
class App;
}

namespace rtcl::cli {

// A bad option value found after CLI11 parsed the command line (e.g. by a
// subcommand's own check); reported like CLI11's own usage errors.
class UsageError : public Error {
 public:
  using Error::Error;
};

// Parses argv into `app` and runs the chosen subcommand's callback. Returns
// the process exit code; help requests print help and return ExitCode::ok.
int run_command_line(CLI::App& app, int argc, char** argv);

}  // namespace rtcl::cli
