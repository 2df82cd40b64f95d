// Fuzz target: bytes -> ray file -> read_rays (and the same bytes as a hit
// file -> read_hits), what `rtcl trace MESH RAYS` reads. Any rtcl::Error is a
// correct answer; anything else is a bug.
#include <cstddef>
#include <cstdint>

#include "fuzz_files.hpp"
#include "rtcl/error.hpp"
#include "rtcl/io/ray_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string path = rtcl::fuzz::write_scratch("input.rays", rtcl::fuzz::as_text(data, size));
  try {
    rtcl::read_rays(path);
  } catch (const rtcl::Error&) {
  }
  try {
    rtcl::read_hits(path);
  } catch (const rtcl::Error&) {
  }
  return 0;
}
