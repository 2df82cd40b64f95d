// Fuzz target: bytes -> mesh file -> load_mesh -> validate, the whole path of
// `rtcl trace MESH`. Input layout: byte 0 picks the format (% 3: .obj, .ply,
// .stl; binary and ASCII PLY/STL are told apart by their content, as for any
// file); for OBJ, the text after a line "#%MTL%" is written as "input.mtl"
// beside it (seeds name it with `mtllib input.mtl`). Any rtcl::Error is a
// correct answer; anything else escaping (another exception, a crash, a leak,
// a hang, an allocation beyond the rss limit) is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_files.hpp"
#include "rtcl/error.hpp"
#include "rtcl/geometry.hpp"
#include "rtcl/scene/mesh_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const char* const extensions[] = {".obj", ".ply", ".stl"};
  const char* extension = extensions[data[0] % 3];
  std::string body(rtcl::fuzz::as_text(data + 1, size - 1));
  if (extension == std::string(".obj")) {
    const std::string marker = "\n#%MTL%\n";
    std::size_t split = body.find(marker);
    rtcl::fuzz::write_scratch("input.mtl", split == std::string::npos ? "" : body.substr(split + marker.size()));
    if (split != std::string::npos) body.resize(split);
  }
  std::string path = rtcl::fuzz::write_scratch(std::string("input") + extension, body);
  try {
    rtcl::LoadedMesh mesh = rtcl::load_mesh(path);
    rtcl::validate(mesh.geometry);
  } catch (const rtcl::Error&) {
  }
  return 0;
}
