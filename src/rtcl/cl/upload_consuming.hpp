// Uploads of host arrays that are freed right after: the copy runs in
// parts, and each part's host pages go back to the operating system once it
// is on the device, so that the host image and its device copy (host memory
// too, on a CPU device) never both hold the whole array.
#pragma once

#include <cstddef>

#include "rtcl/device.hpp"

namespace rtcl {

// Bytes per part: two 2 MiB pages. At most one part exists twice (host
// and device) at a time, which adds to the build's peak memory: 4 MiB is
// about 4 B per triangle of a 1M-triangle BVH (docs/benchmarks.md).
inline constexpr std::size_t kConsumingUploadPartBytes = std::size_t{4} << 20;

// Device::upload(data, bytes, what) in parts of kConsumingUploadPartBytes,
// the whole pages of each part discarded (huge_pages.hpp, discard_pages)
// once it is on the device: the caller must not read [data, data + bytes)
// again, only free the array.
cl::Buffer upload_consuming(const Device& device, void* data, std::size_t bytes, const char* what);

}  // namespace rtcl
