// rtcl: list OpenCL devices, trace ray files, render scenes, benchmark.
#include <cstdio>

#include "cli_errors.hpp"
#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"rtcl: OpenCL ray tracing (acceleration structures, queries, rendering)"};
  app.name("rtcl");
  app.require_subcommand(1);
  rtcl::cli::add_devices_command(app);
  rtcl::cli::add_trace_command(app);
  rtcl::cli::add_render_command(app);
  rtcl::cli::add_structures_command(app);
  rtcl::cli::add_bounds_command(app);
  rtcl::cli::add_bench_command(app);
  if (argc < 2) {  // no subcommand: show what there is, and fail
    std::fputs(app.help().c_str(), stderr);
    return static_cast<int>(rtcl::cli::ExitCode::usage);
  }
  return rtcl::cli::run_command_line(app, argc, argv);
}
