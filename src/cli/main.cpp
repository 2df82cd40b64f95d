// rtcl: list OpenCL devices, trace ray files, render scenes.
#include <cstdio>
#include <exception>

#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"rtcl: OpenCL ray tracing (acceleration structures, queries, rendering)"};
  app.require_subcommand(1);
  rtcl::cli::add_devices_command(app);
  rtcl::cli::add_trace_command(app);
  rtcl::cli::add_render_command(app);
  rtcl::cli::add_structures_command(app);
  if (argc < 2) {  // no subcommand: show what there is, and fail
    app.name("rtcl");
    std::fputs(app.help().c_str(), stderr);
    return 1;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rtcl: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
