// `rtcl structures`: every acceleration structure with its build options,
// their types, defaults, ranges and trade-offs (the registry's declarations,
// rtcl/accel_options.hpp).
#include <cstdio>
#include <string>

#include "commands.hpp"
#include "rtcl/accel.hpp"

namespace rtcl::cli {

namespace {

void print_structures() {
  std::printf("Acceleration structures (--accel NAME or NAME:key=value,...; scene files: \"accel\"):\n");
  for (const StructureSpec& s : structure_specs()) {
    std::printf("\n%s  %s\n", s.name.c_str(), s.summary.c_str());
    if (s.options.empty()) std::printf("    (no options)\n");
    for (const OptionSpec& o : s.options) {
      std::string range = option_range_text(o);
      std::printf("    %-16s %-10s default %-8s %s\n", o.name.c_str(), option_type_name(o.type),
                  format_option_value(o.default_value).c_str(), range.empty() ? "" : range.c_str());
      std::printf("    %-16s %s\n", "", o.help.c_str());
    }
  }
}

}  // namespace

void add_structures_command(CLI::App& app) {
  CLI::App* cmd =
      app.add_subcommand("structures", "List the acceleration structures with their build options and defaults");
  cmd->callback(print_structures);
}

}  // namespace rtcl::cli
