// OpenCL C sources: the kernels embedded at build time, or those under
// $RTCL_KERNEL_DIR when it is set (for kernel development without a rebuild).
#pragma once

#include <string>

namespace rtcl {

// The source of a kernel file (path relative to kernels/) with every
// `#include "path"` replaced by that file's text, once per file, with #line
// markers so that build logs name the original file and line.
// Throws Error naming the file when it does not exist.
std::string kernel_source(const std::string& path);

}  // namespace rtcl
