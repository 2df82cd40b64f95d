// `rtcl devices`: every OpenCL platform and device, with the index that
// --device and RTCL_DEVICE select.
#include <cstdio>
#include <string>

#include "commands.hpp"
#include "rtcl/precision.hpp"
#include "rtcl/device.hpp"
#include "rtcl/error.hpp"

namespace rtcl::cli {

namespace {

std::string human_bytes(std::size_t bytes) {
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
  double value = static_cast<double>(bytes);
  int unit = 0;
  while (value >= 1024.0 && unit < 4) {
    value /= 1024.0;
    ++unit;
  }
  char text[32];
  std::snprintf(text, sizeof text, unit == 0 ? "%.0f %s" : "%.1f %s", value, units[unit]);
  return text;
}

void list() {
  std::vector<DeviceInfo> devices = list_devices();
  if (devices.empty())
    throw Error(
        "no OpenCL device found: install an OpenCL driver (on Debian: apt-get install pocl-opencl-icd; "
        "ocl-icd reads drivers from /etc/OpenCL/vendors or $OCL_ICD_VENDORS)");
  std::string platform;
  for (const DeviceInfo& d : devices) {
    if (d.platform != platform) {
      platform = d.platform;
      std::printf("platform: %s\n", platform.c_str());
    }
    std::printf("  [%zu] %s (%s)\n", d.index, d.name.c_str(), d.type.c_str());
    std::printf("      version: %s\n", d.version.c_str());
    std::printf("      compute units: %u, global memory: %s, max allocation: %s, fp64: %s\n", d.compute_units,
                human_bytes(d.global_mem_bytes).c_str(), human_bytes(d.max_alloc_bytes).c_str(), d.fp64 ? "yes" : "no");
    std::string exact_note = precision_unsupported(d, Precision::exact);
    std::printf("      precision levels: fast, robust, %s\n",
                exact_note.empty() ? "exact (double-precision re-tests on the device)"
                                   : ("no exact (" + exact_note + ")").c_str());
  }
}

}  // namespace

void add_devices_command(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand(
      "devices", "List OpenCL platforms and devices; the index in [N] is what --device N and RTCL_DEVICE=N select");
  cmd->callback(list);
}

}  // namespace rtcl::cli
