#include "version.hpp"

#include <vector>

#include "rtcl/opencl.hpp"
#include "rtcl_version.hpp"

namespace rtcl::cli {

namespace {

// The OpenCL platforms' names; none when the loader finds no driver
// (clGetPlatformIDs then fails with CL_PLATFORM_NOT_FOUND_KHR).
std::vector<std::string> platform_names() {
  cl_uint count = 0;
  if (clGetPlatformIDs(0, nullptr, &count) != CL_SUCCESS || count == 0) return {};
  std::vector<cl_platform_id> ids(count);
  if (clGetPlatformIDs(count, ids.data(), nullptr) != CL_SUCCESS) return {};
  std::vector<std::string> names;
  for (cl_platform_id id : ids) {
    std::size_t size = 0;
    std::string name = "?";
    if (clGetPlatformInfo(id, CL_PLATFORM_NAME, 0, nullptr, &size) == CL_SUCCESS && size > 0) {
      std::string text(size, '\0');
      if (clGetPlatformInfo(id, CL_PLATFORM_NAME, size, text.data(), nullptr) == CL_SUCCESS)
        name = text.c_str();  // drops the terminating NUL
    }
    names.push_back(name);
  }
  return names;
}

}  // namespace

std::string version_text() {
  std::vector<std::string> platforms = platform_names();
  std::string list;
  for (const std::string& p : platforms) list += (list.empty() ? " (" : ", ") + p;
  if (!list.empty()) list += ")";
  return std::string("rtcl ") + RTCL_VERSION + "\ncommit: " + RTCL_GIT_DESCRIBE +
         "\nOpenCL platforms: " + std::to_string(platforms.size()) + list;
}

}  // namespace rtcl::cli
