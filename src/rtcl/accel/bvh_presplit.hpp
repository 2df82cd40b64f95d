// Early split clipping of large triangles before a BVH build (Ernst &
// Greiner 2007, "Early split clipping for bounding volume hierarchies"): a
// triangle whose box is much larger than the scene's typical box enters the
// builder as several references, each the box of the part of the triangle
// on one side of a plane, so that a long or large triangle (a floor, a wall)
// no longer stretches every node above it. A split triangle then sits in
// several leaves (flatten_bvh8 with split_references).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "rtcl/aabb.hpp"
#include "rtcl/geometry.hpp"

namespace rtcl {

// ids[0, triangle_refs) are triangle ids of `geometry` and bounds[] their
// boxes. Every triangle reference whose box's surface area exceeds `factor`
// times the mean over the triangle references is split at the midpoint of
// its longest axis into the boxes of the triangle's parts on either side
// (each within the box split), recursively, until a part's box is at most
// that area, at most kPresplitMaxDepth times per triangle, and while the
// references number at most kPresplitMaxGrowth times the triangles. A split
// reference keeps its place for its first part; the other parts are
// inserted after the triangle references, before the entries that follow
// them (spheres). The parts' boxes together contain the whole triangle (the
// clipped vertices are widened by a few ulps). factor <= 0: no change.
// Returns the new number of triangle references. Deterministic.
std::size_t presplit_triangles(const Geometry& geometry, std::vector<std::uint32_t>& ids, std::vector<Aabb>& bounds,
                               std::size_t triangle_refs, float factor);

inline constexpr int kPresplitMaxDepth = 6;
inline constexpr std::size_t kPresplitMaxGrowth = 2;

}  // namespace rtcl
