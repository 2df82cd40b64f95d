// `rtcl --version`: what a bug report needs to name this build.
#pragma once

#include <string>

namespace rtcl::cli {

// Three lines: "rtcl VERSION", "commit: GIT_DESCRIBE" (git describe
// --always --dirty of the source tree at build time, "unknown" without git)
// and "OpenCL platforms: N" with their names. Asks the OpenCL loader for its
// platforms only: works, with 0, where no driver is installed.
std::string version_text();

}  // namespace rtcl::cli
