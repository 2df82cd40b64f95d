// Octree-R (Whang, Song, Chung, Kim, Shin 1995; lecture, 八叉树: "the split
// planes are chosen more freely than the cube's centre, by a heuristic for
// each of the three directions"): the octree's top-down subdivision over the
// scene's box, each node split on every axis at the candidate plane that
// minimises the estimated cost of a ray crossing it, surface area times
// primitive count summed over the two sides (the probability that a ray
// meeting the node meets a side is proportional to its area). Stored and
// walked as a pointer octree (src/rtcl/accel/octree_ptr.hpp): codes cannot
// address free planes.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/accel/structure_kernels.hpp"
#include "rtcl/accel/octree_build.hpp"
#include "rtcl/accel/octree_ptr.hpp"

namespace rtcl {

struct OctreeRConfig {
  int max_depth = 10;            // 0 .. kOctreePtrMaxDepth
  std::size_t leaf_size = 32;    // k >= 1, as octree-ptr's
  // References per stored primitive the tree may hold (OctreeBuildConfig).
  double ref_budget = 16.0;
  // Candidate planes per axis and node: `bins` - 1 planes evenly spaced
  // inside the node; more find better planes at a longer build.
  int bins = 16;
  // The cost of one traversal step in primitive tests: a split is kept only
  // when it lowers the estimated cost (OctreeBuildConfig::split_cost).
  double traversal_cost = 1.0;
  std::size_t max_alloc_bytes = 0;
  // Occlusion: consecutive rays per work-item, each tested first against
  // the leaf that blocked the previous one; 1 = no such test, 0 = by device
  // (occluder_run_for, accel.hpp).
  std::uint32_t occluder_run = 0;
};

// The plane on one axis of the node box [lo, hi] (the other axes' extents
// e1, e2) minimising area(left) * N(left) + area(right) * N(right) over the
// candidates, where a primitive with clipped extent [pl, pu] counts on the
// left when pl <= p and on the right when pu >= p. Ties go to the
// candidate nearest the centre; the centre when no primitive spans a
// candidate's choice.
float octree_r_split(double lo, double hi, double e1, double e2, const std::vector<double>& prim_lower,
                     const std::vector<double>& prim_upper, int bins);

OctreePtr build_octree_r(const Geometry& geometry, const OctreeRConfig& config = {});

const StructureSpec& octree_r_structure();

std::unique_ptr<Accel> make_octree_r_accel(const Device& device, const Geometry& geometry,
                                           const AccelConfig& config);

std::unique_ptr<Accel> make_octree_r(const Device& device, const Geometry& geometry,
                                     const OctreeRConfig& config = {}, const AccelConfig& accel_config = {});

}  // namespace rtcl
