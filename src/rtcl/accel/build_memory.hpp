// The memory a build needs, estimated from its primitive count before the
// build allocates anything, and checked against what the host and the device
// have: a scene too large is refused with one error naming both sizes
// instead of being left to the kernel's out-of-memory killer or to a
// failed upload after minutes of building.
//
// The estimates are per triangle (a sphere counts half): the peaks `rtcl
// bench` measures (build_peak_bytes, device_bytes) on the random soup and
// on the tessellated surface of 1M triangles, the larger of the two. The
// largest buffer's is a true lower bound (every structure stores each
// triangle once in 40-byte block lanes). A scene within a few percent of
// the limit may be refused or may still run out; where a structure's
// reference count depends on the geometry (grid, octrees, BSP, kd-trees)
// a scene unlike both can need more, and is then stopped by the
// structure's own reference and buffer checks.
//
// Host memory available to a build: MemAvailable of /proc/meminfo, and
// no more than the address-space limit (RLIMIT_AS, `prlimit --as`) leaves
// above what the process maps now; lowered by RTCL_MAX_HOST_BYTES (a
// positive decimal number of bytes; for tests and for sharing a machine).
#pragma once

#include <cstddef>
#include <string>

namespace rtcl {

class Device;

struct BuildFootprint {
  // Peak host bytes per primitive the build allocates beyond the caller's
  // Geometry (its temporaries and the flattened structure before upload).
  double host_bytes_per_primitive = 0.0;
  // Device bytes per primitive of the uploaded structure (all its buffers)
  // and of its largest single buffer.
  double device_bytes_per_primitive = 0.0;
  double largest_buffer_bytes_per_primitive = 0.0;
};

// Bytes of host memory a build may still take (see above); SIZE_MAX when
// /proc/meminfo cannot be read and nothing else limits it. Throws Error for
// a malformed RTCL_MAX_HOST_BYTES.
std::size_t available_host_bytes();

// Throws Error naming `what` (e.g. `make_accel "bvh" over soup:count=N`),
// the primitive count and both numbers when the estimated peak host bytes
// exceed host_available_bytes, or the structure's device bytes exceed
// global_mem_bytes, or its largest buffer max_alloc_bytes. With
// `device_in_host_memory` (a CPU device, whose buffers are host memory) the
// host peak includes the device bytes.
void check_build_memory(const BuildFootprint& footprint, std::size_t primitives, const std::string& what,
                        std::size_t host_available_bytes, std::size_t max_alloc_bytes, std::size_t global_mem_bytes,
                        const std::string& device_name, bool device_in_host_memory = false);

// The same against available_host_bytes() and the device's limits
// (DeviceInfo, lowered by RTCL_MAX_ALLOC_BYTES / RTCL_MAX_GLOBAL_BYTES);
// a device of type "cpu" holds its buffers in host memory.
void check_build_memory(const BuildFootprint& footprint, std::size_t primitives, const std::string& what,
                        const Device& device);

}  // namespace rtcl
