// rtcl: list OpenCL devices, trace ray files, render scenes, benchmark.
// The command line's conventions (exit codes, messages, environment):
// docs/cli.md.
#include "cli_errors.hpp"
#include "commands.hpp"
#include "version.hpp"

int main(int argc, char** argv) {
  CLI::App app{"rtcl: OpenCL ray tracing (acceleration structures, queries, rendering)"};
  app.name("rtcl");
  app.require_subcommand(1);
  app.set_version_flag("--version", rtcl::cli::version_text,
                       "Print the version, the git commit and the OpenCL platforms found, and exit");
  rtcl::cli::add_devices_command(app);
  rtcl::cli::add_trace_command(app);
  rtcl::cli::add_render_command(app);
  rtcl::cli::add_structures_command(app);
  rtcl::cli::add_bounds_command(app);
  rtcl::cli::add_bench_command(app);
  return rtcl::cli::run_command_line(app, argc, argv);
}
