#include "rtcl/cl/upload_consuming.hpp"

#include <algorithm>

#include "rtcl/opencl.hpp"
#include "rtcl/huge_pages.hpp"

namespace rtcl {

cl::Buffer upload_consuming(const Device& device, void* data, std::size_t bytes, const char* what) {
  cl::Buffer buffer = device.allocate(bytes, what, CL_MEM_READ_ONLY);
  auto* bytes_in = static_cast<unsigned char*>(data);
  for (std::size_t offset = 0; offset < bytes; offset += kConsumingUploadPartBytes) {
    const std::size_t n = std::min(kConsumingUploadPartBytes, bytes - offset);
    with_cl_errors([&] { device.queue().enqueueWriteBuffer(buffer, CL_TRUE, offset, n, bytes_in + offset); });
    discard_pages(bytes_in + offset, n);
  }
  return buffer;
}

}  // namespace rtcl
