// The library's errors name its API parameters (accel "TEXT", make_accel
// name "TEXT", precision "NAME"); rtcl's name the flags a user typed
// (--accel TEXT, --precision NAME). These wrappers check a flag's value
// with the library and report a problem under the flag's name, as a usage
// error (exit 2, cli_errors.hpp).
#pragma once

#include <string>
#include <utility>

#include "cli_errors.hpp"
#include "rtcl/accel_options.hpp"
#include "rtcl/device.hpp"
#include "rtcl/error.hpp"
#include "rtcl/precision.hpp"
#include "rtcl/scene/scene_description.hpp"

namespace rtcl::cli {

// parse_accel_spec under "--accel TEXT": "--accel grid:lambda=-1: lambda
// must be > 0 and <= 1024".
AccelSpec parse_accel_flag(const std::string& text);

// parse_precision under "--precision NAME": "--precision precise: unknown
// precision level (known: fast, robust, exact)".
Precision parse_precision_flag(const std::string& name);

// require_precision under "--precision NAME": "--precision exact: exact
// needs double precision on the device (cl_khr_fp64), which DEVICE lacks".
void require_precision_flag(const DeviceInfo& device, Precision precision);

// Device::open(selector) under "--device SELECTOR": "--device 99: no such
// device (there are 1; see `rtcl devices`)"; with no selector, a bad
// $RTCL_DEVICE as "RTCL_DEVICE=99: ...". No OpenCL device at all stays a
// plain Error (exit 1).
Device open_device_flag(const std::string& selector);

// builtin_scene(name, $RTCL_SCENES_DIR) under "--builtin NAME":
// "--builtin x: unknown built-in scene (known: default, showcase, forest)".
SceneDescription builtin_scene_flag(const std::string& name);

// The image formats --output takes, by extension: 8-bit sRGB and linear
// float ones (rtcl/render/image.hpp writes them), e.g. ".png, .jpg, ...".
std::string image_formats_text();

// Throws UsageError "--output PATH: unsupported image format '.xyz' (known:
// ...)" unless PATH ends in one of those extensions (any case).
void check_image_extension_flag(const std::string& path);

// check_image_extension_flag, then check_image_path (an Error, exit 1, when
// its directory is not writable).
void check_image_output_flag(const std::string& path);

// When the library raised `e` about the structure `accel` (accel "TEXT",
// make_accel name "TEXT", Renderer accel "TEXT"): the same problem under
// "--accel TEXT"; else "".
std::string accel_flag_message(const Error& e, const std::string& accel);

// Runs `work`; a library error about the structure `accel` names --accel
// instead (accel_flag_message) and is a usage error; other errors pass
// unchanged.
template <class Work>
decltype(auto) naming_accel_flag(const std::string& accel, Work&& work) {
  try {
    return std::forward<Work>(work)();
  } catch (const Error& e) {
    std::string renamed = accel_flag_message(e, accel);
    if (renamed.empty()) throw;
    throw UsageError(renamed);
  }
}

}  // namespace rtcl::cli
