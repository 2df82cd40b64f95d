// The exit codes of `rtcl` (docs/cli.md, "Exit codes"). Every failure path
// of every subcommand ends in one of these.
#pragma once

namespace rtcl::cli {

enum class ExitCode : int {
  ok = 0,
  // bad input or failed run: an unreadable or malformed file, an unwritable
  // output, no OpenCL device at all, a device error or out of memory
  failed = 1,
  // bad command line: an unknown option or subcommand, a missing argument,
  // an option value out of range or unknown (a structure option, a device
  // index that does not exist, an unsupported image extension, ...), or
  // RTCL_DEVICE naming no device
  usage = 2,
};

}  // namespace rtcl::cli
