// Where the benchmarks and `rtcl bench` find the shared meshes (never copied
// into the repository): $RTCL_SCENES_DIR names the directory.
#pragma once

#include <string>

namespace rtcl::bench {

// $RTCL_SCENES_DIR when it is set and not empty, else "". `rtcl bench`
// uses it when --scenes-dir is not given, and has no default beyond it.
std::string scenes_dir_from_env();

// The benchmark programs' directory: $RTCL_SCENES_DIR, else ../shared/scenes
// beside the source tree (fixed when the build is configured).
std::string scenes_dir();

}  // namespace rtcl::bench
