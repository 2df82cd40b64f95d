// Each `rtcl` subcommand lives in its own file and registers itself here.
#pragma once

#include <CLI/CLI.hpp>

namespace rtcl::cli {

// Each adds its subcommand to `app`; the subcommand's callback does the work
// and throws rtcl::Error (or std::exception) on failure.
void add_devices_command(CLI::App& app);
void add_trace_command(CLI::App& app);
void add_render_command(CLI::App& app);
void add_structures_command(CLI::App& app);
void add_bounds_command(CLI::App& app);
void add_bench_command(CLI::App& app);

}  // namespace rtcl::cli
