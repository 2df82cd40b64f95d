// Fuzz target: bytes -> scene file -> load_scene -> validate -> flatten, what
// `rtcl render SCENE` does before it opens a device. Scene files may name the
// fixtures of fuzz_files.hpp ("mesh.obj", "folder.obj") and themselves
// ("input.json"). Any rtcl::Error is a correct answer; anything else is a bug.
#include <cstddef>
#include <cstdint>

#include "fuzz_files.hpp"
#include "rtcl/error.hpp"
#include "rtcl/scene/scene_description.hpp"
#include "rtcl/scene/scene_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string path = rtcl::fuzz::write_scratch("input.json", rtcl::fuzz::as_text(data, size));
  try {
    rtcl::SceneDescription scene = rtcl::load_scene(path);
    rtcl::validate(scene);
    rtcl::flatten(scene);
  } catch (const rtcl::Error&) {
  }
  return 0;
}
