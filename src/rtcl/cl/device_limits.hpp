// Memory limits rtcl holds a device to: the device's own (largest buffer,
// global memory), optionally lowered by the environment, a knob for tests and
// for sharing a device:
//   RTCL_MAX_ALLOC_BYTES   largest single buffer, in bytes
//   RTCL_MAX_GLOBAL_BYTES  all of rtcl's live buffers on the device together
// A value can only lower a limit; one that is not a positive decimal integer
// is an error naming the variable.
#pragma once

#include <cstddef>
#include <string>

namespace rtcl {

struct DeviceLimits {
  std::size_t max_alloc_bytes = 0;
  std::size_t global_mem_bytes = 0;
};

// The device's limits (CL_DEVICE_MAX_MEM_ALLOC_SIZE, CL_DEVICE_GLOBAL_MEM_SIZE)
// lowered by RTCL_MAX_ALLOC_BYTES and RTCL_MAX_GLOBAL_BYTES when set.
DeviceLimits limits_with_overrides(DeviceLimits device);

// Whether `live_bytes` (what rtcl already holds on the device) plus `bytes`
// stay within limits.global_mem_bytes (without overflow).
bool fits_global_memory(const DeviceLimits& limits, std::size_t bytes, std::size_t live_bytes);

// Throws Error, naming `what`, the device and both numbers, when a buffer of
// `bytes` is larger than limits.max_alloc_bytes or when `live_bytes` (what
// rtcl already holds there) plus `bytes` exceed limits.global_mem_bytes.
void check_allocation(const DeviceLimits& limits, std::size_t bytes, std::size_t live_bytes, const std::string& what,
                      const std::string& device_name);

}  // namespace rtcl
