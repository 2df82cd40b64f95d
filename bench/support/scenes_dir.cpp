#include "bench/support/scenes_dir.hpp"

#include <cstdlib>

namespace rtcl::bench {

std::string scenes_dir_from_env() {
  const char* dir = std::getenv("RTCL_SCENES_DIR");
  return dir && *dir ? dir : "";
}

std::string scenes_dir() {
  std::string dir = scenes_dir_from_env();
  return dir.empty() ? RTCL_DEFAULT_SCENES_DIR : dir;
}

}  // namespace rtcl::bench
