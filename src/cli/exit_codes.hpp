// The exit codes of `rtcl`, as README.md ("Robustness") documents them. Every
// failure path of every subcommand ends in one of these.
#pragma once

namespace rtcl::cli {

enum class ExitCode : int {
  ok = 0,
  failed = 1,  // bad input file, unwritable output, no device, device error
  usage = 2,   // bad command line: unknown flag, missing argument, bad option value
};

}  // namespace rtcl::cli
