// The scene file: JSON a person can write by hand (comments allowed), read
// strictly. Format and an example: docs/file-formats.md. Paths inside are
// relative to the scene file's directory.
//
// MTL materials of meshes become scene materials: Ka -> ambient (Kd when Ka
// is black), Kd -> diffuse, Ks -> specular, Ns -> shininess, Ke -> emission,
// Ni -> ior (1 when not positive), d < 1 -> kt = 1 - d; kr = 0.
#pragma once

#include <filesystem>
#include <string>

#include "rtcl/scene/mesh_io.hpp"
#include "rtcl/scene/scene_description.hpp"

namespace rtcl {

// Reads and validates the scene file at `path`. Throws Error naming the file
// (and, for content errors, the key path such as objects[2].radius) for: a
// missing or unreadable file, malformed JSON (with line and column), an
// unknown key, a value of the wrong type or out of range, a missing required
// key, an unknown material name, or a mesh that cannot be loaded.
SceneDescription load_scene(const std::string& path);

// The same from text; `source` names it in errors and `base_dir` resolves
// relative mesh paths.
SceneDescription parse_scene(const std::string& text, const std::string& source, const std::filesystem::path& base_dir);

// The scene material an MTL material maps to (see above).
Material material_from_mtl(const MeshMaterial& m);

}  // namespace rtcl
