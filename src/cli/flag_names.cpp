#include "flag_names.hpp"

#include <algorithm>

#include "rtcl/scene/showcase_scene.hpp"

namespace rtcl::cli {

AccelSpec parse_accel_flag(const std::string& text) { return parse_accel_spec(text, "--accel " + text); }

Precision parse_precision_flag(const std::string& name) {
  const std::vector<std::string>& names = precision_names();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    std::string known;
    for (const std::string& n : names) known += (known.empty() ? "" : ", ") + n;
    throw Error("--precision " + name + ": unknown precision level (known: " + known + ")");
  }
  return parse_precision(name);
}

void require_precision_flag(const DeviceInfo& device, Precision precision) {
  std::string why = precision_unsupported(device, precision);
  if (!why.empty()) throw Error("--precision " + std::string(precision_name(precision)) + ": " + why);
}

namespace {

// `what` with the library's `parameter "value": ` prefix replaced by the
// flag's `flag value: `; "" when it has no such prefix.
std::string renamed(const std::string& what, const std::string& parameter, const std::string& value,
                    const std::string& flag) {
  const std::string prefix = parameter + " \"" + value + "\": ";
  if (what.rfind(prefix, 0) != 0) return "";
  return flag + " " + value + ": " + what.substr(prefix.size());
}

}  // namespace

Device open_device_flag(const std::string& selector) {
  try {
    return Device::open(selector);
  } catch (const Error& e) {
    std::string message = renamed(e.what(), "Device::open selector", selector, "--device");
    if (message.empty()) throw;
    throw Error(message);
  }
}

SceneDescription builtin_scene_flag(const std::string& name) {
  try {
    return builtin_scene(name);
  } catch (const Error& e) {
    std::string message = renamed(e.what(), "builtin_scene name", name, "--builtin");
    if (message.empty()) throw;
    throw Error(message);
  }
}

std::string accel_flag_message(const Error& e, const std::string& accel) {
  const std::string what = e.what();
  for (const char* parameter : {"accel", "make_accel name", "Renderer accel"}) {
    std::string prefix = std::string(parameter) + " \"" + accel + "\": ";
    if (what.rfind(prefix, 0) == 0) return "--accel " + accel + ": " + what.substr(prefix.size());
  }
  return "";
}

}  // namespace rtcl::cli
