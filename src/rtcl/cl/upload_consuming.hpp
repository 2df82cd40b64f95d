// Uploads of host arrays that are freed right after: the copy runs in
// parts, and each part's host pages go back to the operating system once it
// is on the device, so that the host image and its device copy (host memory
// too, on a CPU device) never both hold the whole array.
#pragma once

#include <cstddef>

#include "rtcl/device.hpp"

namespace rtcl {

// Device::upload(data, bytes, what), after which the whole pages of [data,
// data + bytes) are discarded (huge_pages.hpp, discard_pages): the caller
// must not read them again, only free the array.
cl::Buffer upload_consuming(const Device& device, void* data, std::size_t bytes, const char* what);

}  // namespace rtcl
