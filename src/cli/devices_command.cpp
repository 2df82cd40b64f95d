#include "commands.hpp"

namespace rtcl::cli {

void add_devices_command(CLI::App& app) { app.add_subcommand("devices", "(not yet available)"); }

}  // namespace rtcl::cli
