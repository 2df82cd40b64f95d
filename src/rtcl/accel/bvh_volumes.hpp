// Per-node bounding-volume choice for the 8-wide BVH (lecture, 层次包围体:
// each node may choose its volume type). After the build, each node either
// keeps its children's boxes alone or adds a second, float8 filter by the
// children's exact bounding spheres (Welzl, rtcl/bounds/sphere_bounds.hpp),
// whichever has the lower expected cost:
//
//   cost(node) = box + [sphere] + sum over children k of P_k * cost(k),
//   P_k = area(volume_k) / area(node's box),
//
// where volume_k is child k's box, or with the filter the intersection of
// its box and sphere (its area taken as the smaller of the two: an upper
// bound, so the filter's gain is never overstated), area ratios being the
// probability that a ray entering the node enters the child (Cauchy's
// formula for convex bodies, the SAH's assumption), and cost(leaf) = block.
// Decided bottom-up, so every child's cost is its chosen one.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "rtcl/accel/bvh.hpp"
#include "rtcl/layouts.hpp"

namespace rtcl {

// Relative test costs, in units of one node's eight-box float8 slab test.
// Defaults measured on PoCL (bench volume_cost/bunny/*, 65,536 diffuse rays
// x 256 records, median of 3): box 107 ms, sphere filter 145 ms (1.36x),
// triangle block 867 ms (8.1x).
struct VolumeCosts {
  float sphere = 1.3f;  // the eight-sphere float8 filter of one node
  float block = 8.0f;   // one leaf block (eight triangle tests in float8)
};

struct BvhSphereFilters {
  std::vector<rtcl_i32> sphere_of;  // per node: index into records, or -1
  std::vector<Bvh8Spheres> records;
  std::size_t sphere_lanes = 0;     // children with a sphere, over all records
  double aabb_cost = 0.0;           // expected cost of a ray entering the root, boxes only
  double chosen_cost = 0.0;         // the same with the chosen filters
};

// Chooses the filters for `bvh` (flatten_bvh8's output: children after
// their parents). Children holding sphere primitives keep their box alone
// (r < 0). Throws Error naming `source` for costs that are negative or not
// finite.
BvhSphereFilters choose_sphere_filters(const Bvh8& bvh, const VolumeCosts& costs, const std::string& source);

}  // namespace rtcl
