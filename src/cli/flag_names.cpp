#include "flag_names.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>

#include "rtcl/render/image.hpp"
#include "rtcl/scene/showcase_scene.hpp"

namespace rtcl::cli {

AccelSpec parse_accel_flag(const std::string& text) {
  return as_usage_error([&] { return parse_accel_spec(text, "--accel " + text); });
}

Precision parse_precision_flag(const std::string& name) {
  const std::vector<std::string>& names = precision_names();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    std::string known;
    for (const std::string& n : names) known += (known.empty() ? "" : ", ") + n;
    throw UsageError("--precision " + name + ": unknown precision level (known: " + known + ")");
  }
  return parse_precision(name);
}

void require_precision_flag(const DeviceInfo& device, Precision precision) {
  std::string why = precision_unsupported(device, precision);
  if (!why.empty()) throw UsageError("--precision " + std::string(precision_name(precision)) + ": " + why);
}

namespace {

// `what` with the library's `parameter "value": ` prefix replaced by
// `flag value: ` (`flag=value: ` for an environment variable); "" when it
// has no such prefix.
std::string renamed(const std::string& what, const std::string& parameter, const std::string& value,
                    const std::string& flag, const char* joint = " ") {
  const std::string prefix = parameter + " \"" + value + "\": ";
  if (what.rfind(prefix, 0) != 0) return "";
  return flag + joint + value + ": " + what.substr(prefix.size());
}

// The image formats --output takes; write_image treats the float ones as
// linear (rtcl/render/image.hpp).
constexpr const char* srgb_extensions[] = {".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".ppm"};
constexpr const char* linear_extensions[] = {".exr", ".hdr"};

}  // namespace

Device open_device_flag(const std::string& selector) {
  try {
    return Device::open(selector);
  } catch (const Error& e) {
    std::string message = renamed(e.what(), "Device::open selector", selector, "--device");
    if (const char* env = std::getenv("RTCL_DEVICE"); message.empty() && selector.empty() && env && *env)
      message = renamed(e.what(), "RTCL_DEVICE", env, "RTCL_DEVICE", "=");
    if (message.empty()) throw;
    throw UsageError(message);
  }
}

SceneDescription builtin_scene_flag(const std::string& name) {
  try {
    const char* scenes_dir = std::getenv("RTCL_SCENES_DIR");
    return builtin_scene(name, scenes_dir ? scenes_dir : "");
  } catch (const Error& e) {
    std::string message = renamed(e.what(), "builtin_scene name", name, "--builtin");
    if (message.empty()) throw;
    throw UsageError(message);
  }
}

std::string image_formats_text() {
  std::string out;
  for (const char* e : srgb_extensions) out += (out.empty() ? "" : ", ") + std::string(e);
  out += " (8-bit sRGB); ";
  std::string linear;
  for (const char* e : linear_extensions) linear += (linear.empty() ? "" : ", ") + std::string(e);
  return out + linear + " (linear float)";
}

void check_image_extension_flag(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  bool known = false;
  for (const char* e : srgb_extensions) known = known || ext == e;
  for (const char* e : linear_extensions) known = known || ext == e;
  if (!known)
    throw UsageError("--output " + path + ": " +
                     (ext.empty() ? std::string("no file extension to choose the image format by")
                                  : "unsupported image format '" + ext + "'") +
                     " (known: " + image_formats_text() + ")");
}

void check_image_output_flag(const std::string& path) {
  check_image_extension_flag(path);
  check_image_path(path);
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
