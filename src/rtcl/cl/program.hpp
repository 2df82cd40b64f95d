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
// The same for a kernel file that is not the library's (bench/kernels/):
// `text` read as `path`, its includes from the library's kernels.
std::string kernel_source(const std::string& path, const std::string& text);

// A build log with the compiler's positions in the assembled source
// ("<kernel>:N:", as NVIDIA's OpenCL compiler writes them: it ignores #line)
// rewritten as "file:line:" of the original kernel file, read from the #line
// markers of `source` (what kernel_source returned). Positions already named
// by file, and lines without a marker before them, are left as they are.
std::string name_source_lines(const std::string& log, const std::string& source);

}  // namespace rtcl
