#include "commands.hpp"

namespace rtcl::cli {

void add_trace_command(CLI::App& app) { app.add_subcommand("trace", "(not yet available)"); }

}  // namespace rtcl::cli
