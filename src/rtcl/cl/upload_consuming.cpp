#include "rtcl/cl/upload_consuming.hpp"

#include <algorithm>

#include "rtcl/opencl.hpp"
#include "rtcl/huge_pages.hpp"

namespace rtcl {

namespace {

// Bytes per part: a few 2 MiB pages, so that the host memory held beside
// the device copy stays small and the writes stay few.
constexpr std::size_t kPartBytes = std::size_t{16} << 20;

}  // namespace

cl::Buffer upload_consuming(const Device& device, void* data, std::size_t bytes, const char* what) {
  cl::Buffer buffer = device.allocate(bytes, what, CL_MEM_READ_ONLY);
  auto* bytes_in = static_cast<unsigned char*>(data);
  for (std::size_t offset = 0; offset < bytes; offset += kPartBytes) {
    const std::size_t n = std::min(kPartBytes, bytes - offset);
    with_cl_errors([&] { device.queue().enqueueWriteBuffer(buffer, CL_TRUE, offset, n, bytes_in + offset); });
    discard_pages(bytes_in + offset, n);
  }
  return buffer;
}

}  // namespace rtcl
