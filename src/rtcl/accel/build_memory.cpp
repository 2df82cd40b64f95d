#include "rtcl/accel/build_memory.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string_view>

#include "rtcl/device.hpp"
#include "rtcl/error.hpp"

namespace rtcl {

namespace {

// The value in kB of `key` in a /proc file of "Key:   N kB" lines, in
// bytes; SIZE_MAX when absent.
std::size_t proc_kilobytes(const char* path, std::string_view key) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line))
    if (line.size() > key.size() && line.compare(0, key.size(), key) == 0 && line[key.size()] == ':') {
      std::size_t kb = 0;
      const std::size_t digits = line.find_first_not_of(" \t", key.size() + 1);  // /proc/self/status: a tab
      if (digits != std::string::npos &&
          std::from_chars(line.data() + digits, line.data() + line.size(), kb).ec == std::errc())
        return kb * 1024;
    }
  return SIZE_MAX;
}

std::size_t estimate(double per_primitive, std::size_t primitives) {
  double bytes = per_primitive * static_cast<double>(primitives);
  return bytes >= 1.8e19 ? SIZE_MAX : static_cast<std::size_t>(bytes);
}

}  // namespace

std::size_t available_host_bytes() {
  std::size_t available = proc_kilobytes("/proc/meminfo", "MemAvailable");
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
    const std::size_t mapped = proc_kilobytes("/proc/self/status", "VmSize");
    const auto cap = static_cast<std::size_t>(limit.rlim_cur);
    if (mapped != SIZE_MAX) available = std::min(available, mapped >= cap ? 0 : cap - mapped);
  }
  if (const char* text = std::getenv("RTCL_MAX_HOST_BYTES"); text && *text) {
    std::size_t value = 0;
    const char* end = text + std::strlen(text);
    auto [stop, ec] = std::from_chars(text, end, value);
    if (ec != std::errc() || stop != end || value == 0)
      throw Error(std::string("RTCL_MAX_HOST_BYTES='") + text + "': expected a positive number of bytes");
    available = std::min(available, value);
  }
  return available;
}

void check_build_memory(const BuildFootprint& footprint, std::size_t primitives, const std::string& what,
                        std::size_t host_available_bytes, std::size_t max_alloc_bytes, std::size_t global_mem_bytes,
                        const std::string& device_name, bool device_in_host_memory) {
  const std::string count = " (" + std::to_string(primitives) + " primitives)";
  const std::size_t host = estimate(footprint.host_bytes_per_primitive +
                                        (device_in_host_memory ? footprint.device_bytes_per_primitive : 0.0),
                                    primitives);
  if (host > host_available_bytes)
    throw Error(what + count + ": the build needs about " + std::to_string(host) +
                " bytes of host memory at its peak, more than the " + std::to_string(host_available_bytes) +
                " bytes available (MemAvailable, the address-space limit or RTCL_MAX_HOST_BYTES)");
  const std::size_t largest = estimate(footprint.largest_buffer_bytes_per_primitive, primitives);
  if (largest > max_alloc_bytes)
    throw Error(what + count + ": its largest buffer needs about " + std::to_string(largest) +
                " bytes, more than the largest buffer " + device_name + " allows (" + std::to_string(max_alloc_bytes) +
                " bytes, CL_DEVICE_MAX_MEM_ALLOC_SIZE)");
  const std::size_t device = estimate(footprint.device_bytes_per_primitive, primitives);
  if (device > global_mem_bytes)
    throw Error(what + count + ": the structure needs about " + std::to_string(device) +
                " bytes on the device, more than the global memory of " + device_name + " (" +
                std::to_string(global_mem_bytes) + " bytes)");
}

void check_build_memory(const BuildFootprint& footprint, std::size_t primitives, const std::string& what,
                        const Device& device) {
  const DeviceInfo& info = device.info();
  check_build_memory(footprint, primitives, what, available_host_bytes(), info.max_alloc_bytes, info.global_mem_bytes,
                     info.name, info.type == "cpu");
}

}  // namespace rtcl
