// A SceneDescription as one flat byte string and back, for sending a loaded scene
// (meshes included) to other processes (rtcl render under mpirun
// broadcasts it from rank 0). The encoding is this build's own: both ends
// run the same rtcl; little-endian hosts; it starts with a magic and a
// version so a mismatch is an error, not a wrong scene.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "rtcl/scene/scene_description.hpp"

namespace rtcl {

// Every field of the scene, in declaration order; floats and doubles bit
// for bit. Mesh shapes go once each, before the meshes that name them by
// index: meshes that share a shape share it after scene_from_bytes too.
std::vector<std::byte> scene_to_bytes(const SceneDescription& scene);

// The scene scene_to_bytes encoded. Throws Error naming `what` (where the
// bytes came from) when they are truncated, carry extra bytes, another
// magic or version, or a count larger than the bytes that remain.
SceneDescription scene_from_bytes(std::span<const std::byte> bytes, const std::string& what);

}  // namespace rtcl
