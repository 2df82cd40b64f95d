// Candidate culling of the beams below the viewing beam with a BVH (the
// binary SAH tree of the real-world triangles, built and walked on the
// host): a beam's bounding frustum, i.e. the planes through the eye and each
// edge of its cross-section, the near plane and the far side of its last
// interface (mirror or refracting polygon), is taken from the beam's world
// back to real-world coordinates (a plane L of the world is L' = T^T L for
// the world's transform T, since L . (T p) = (T^T L) . p) and tested against
// the nodes' boxes. Conservative: every triangle whose screen polygon in the
// beam's world meets the cross-section is kept; the exact 2D overlap test
// (tile_beams.hpp) then drops the rest.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/accel/build_tree.hpp"
#include "rtcl/beam/polygon2d.hpp"
#include "rtcl/beam/screen_space.hpp"

namespace rtcl::beam {

// Half-spaces plane . (p, 1) >= 0 of real-world points p.
struct BeamFrustum {
  std::vector<glm::dvec4> planes;
};

// The frustum of the beam over `section` (convex, pixels) in the world whose
// points are to_virtual * p (p real), clipped to keep_plane . (q, 1) >= 0
// (q in that world) when keep_plane is given.
BeamFrustum beam_frustum(const ScreenSpace& screen, const Convex& section, const glm::dmat4& to_virtual,
                         const glm::dvec4* keep_plane);

// Appends to `prims` the ids in the leaves of `bvh` whose boxes (and their
// ancestors') are not wholly outside one of the frustum's planes. Boxes are
// widened by 1e-9 of their coordinates' magnitude against rounding.
void cull(const BuildTree& bvh, const BeamFrustum& frustum, std::vector<std::uint32_t>& prims);

}  // namespace rtcl::beam
