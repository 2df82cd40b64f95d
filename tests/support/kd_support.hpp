// What the BSP and kd-tree tests share (tests/bsp_test.cpp,
// tests/kdtree_test.cpp): rays aimed at a tree's split planes, and the
// comparison of a structure's answers with brute force.
#pragma once

#include <cstdint>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/accel/kdtree_nodes.hpp"

namespace rtcl::test {

// Rays that stress the interval traversal: lying in split planes (a zero
// component of either sign), starting on planes and inside leaves,
// axis-parallel with +0 / -0 in the other components, through the corners
// of leaves, from outside the root box, in every octant.
std::vector<Ray> split_plane_rays(const KdTree& tree, std::uint32_t seed, std::size_t count);

// `accel` and brute force answer both queries identically: for closest hit
// the same hit / miss and t (bit for bit unless `level` is fast, where the
// programs may round differently: within 1e-5 relative, or 16 float ulps of
// the scene's scale along the ray), for any hit the
// same hit / miss. The primitive may differ only on an exact tie of t
// (triangles sharing the edge or vertex hit): with `judge`, robust answers
// are judged against the double-precision reference, which accepts such a
// tie and nothing else.
void expect_same_as_brute(const Accel& accel, const Geometry& geometry, const std::vector<Ray>& rays,
                          Precision level, bool judge = true);

}  // namespace rtcl::test
