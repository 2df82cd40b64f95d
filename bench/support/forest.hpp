// The instanced forest of bench/scenes/instances_bench.cpp and `rtcl bench
// --instances`: copies of one mesh placed on a square grid, and a camera
// above them. Deterministic: the same count, box and seed give the same
// placements.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "bench/support/scene_catalog.hpp"
#include "rtcl/aabb.hpp"
#include "rtcl/scene.hpp"

namespace rtcl::bench {

// `count` placements of a mesh whose box is `bounds` on a square grid in
// the xz plane (spacing 1.3 times the box's larger horizontal extent), each
// centred, turned about y by 0 .. 360 degrees and scaled by 0.8 .. 1.2.
std::vector<Transform> forest_placements(std::size_t count, const Aabb& bounds, std::uint32_t seed);

// A camera above one corner of that grid looking at its centre (a field
// of view of 50 degrees).
Camera forest_camera(std::size_t count, const Aabb& bounds);

// The ms (CommitStats::build_ms) of `repeat` commits of `scene`, each after
// every instance ids[k] was set to placements[k] again (set_transform): a
// pure instance edit, so each commit builds the top level alone.
std::vector<double> top_level_commit_ms(Scene& scene, const std::vector<InstanceId>& ids,
                                        const std::vector<Transform>& placements, int repeat);

}  // namespace rtcl::bench
