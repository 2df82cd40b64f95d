#include "rtcl/cl/device_limits.hpp"

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <cstring>

#include "rtcl/error.hpp"

namespace rtcl {

namespace {

// The limit `name` sets, or `fallback` when it is unset or empty.
std::size_t env_limit(const char* name, std::size_t fallback) {
  const char* text = std::getenv(name);
  if (!text || !*text) return fallback;
  std::size_t value = 0;
  const char* end = text + std::strlen(text);
  auto [stop, ec] = std::from_chars(text, end, value);
  if (ec != std::errc() || stop != end || value == 0)
    throw Error(std::string(name) + "='" + text + "': expected a positive number of bytes");
  return std::min(value, fallback);
}

}  // namespace

DeviceLimits limits_with_overrides(DeviceLimits device) {
  device.max_alloc_bytes = env_limit("RTCL_MAX_ALLOC_BYTES", device.max_alloc_bytes);
  device.global_mem_bytes = env_limit("RTCL_MAX_GLOBAL_BYTES", device.global_mem_bytes);
  return device;
}

bool fits_global_memory(const DeviceLimits& limits, std::size_t bytes, std::size_t live_bytes) {
  return bytes <= limits.global_mem_bytes && live_bytes <= limits.global_mem_bytes - bytes;
}

void check_allocation(const DeviceLimits& limits, std::size_t bytes, std::size_t live_bytes, const std::string& what,
                      const std::string& device_name) {
  if (bytes > limits.max_alloc_bytes)
    throw Error(what + ": " + std::to_string(bytes) + " bytes exceed the largest buffer " + device_name +
                " allows (" + std::to_string(limits.max_alloc_bytes) + " bytes)");
  if (!fits_global_memory(limits, bytes, live_bytes))
    throw Error(what + ": " + std::to_string(bytes) + " bytes, with the " + std::to_string(live_bytes) +
                " bytes rtcl already holds there, exceed the global memory of " + device_name + " (" +
                std::to_string(limits.global_mem_bytes) + " bytes)");
}

}  // namespace rtcl
