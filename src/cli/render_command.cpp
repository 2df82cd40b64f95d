#include "commands.hpp"

namespace rtcl::cli {

void add_render_command(CLI::App& app) { app.add_subcommand("render", "(not yet available)"); }

}  // namespace rtcl::cli
