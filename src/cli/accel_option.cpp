#include "accel_option.hpp"

#include <algorithm>
#include <vector>

#include "rtcl/accel.hpp"

namespace rtcl::cli {

namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

bool registered(const std::string& name) {
  std::vector<std::string> names = accel_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

// "" when `spec` names a registered structure, else the problem.
std::string accel_problem(const std::string& spec) {
  std::string name = spec.substr(0, spec.find(':'));
  if (registered(name)) return {};
  return "unknown acceleration structure '" + name + "' (known: " + joined(accel_names()) + ")";
}

}  // namespace

std::string default_accel() {
  std::vector<std::string> names = accel_names();
  if (registered("bvh")) return "bvh";
  return names.empty() ? "brute" : names.front();
}

CLI::Option* add_accel_option(CLI::App& cmd, std::string& spec) {
  return cmd.add_option("--accel", spec,
                        "acceleration structure: " + joined(accel_names()) + " (default: " + default_accel() +
                            "), with build options as NAME:key=value,... e.g. grid:lambda=4 or grid:res=64x32x16 "
                            "(`rtcl structures` lists every option and default)")
      ->check(CLI::Validator(accel_problem, "NAME", "registered structure"));
}

std::string accel_or_default(const std::string& spec) { return spec.empty() ? default_accel() : spec; }

}  // namespace rtcl::cli
