// Per-node bounding-volume choice for the 8-wide BVH (lecture, 层次包围体:
// each node may choose its volume type). After the build, each node keeps
// its children's boxes alone or adds one float8 filter of its children by
// volumes of one kind (bvh_child_volumes.hpp): exact (Welzl) bounding
// spheres, the body-diagonal slabs of the 14-DOP, or oriented boxes. The
// choice is per node, not per child slot, because a filter's float8 test
// costs the same for one lane as for eight: a node pays for each kind it
// runs, so it runs at most one.
//
// Expected cost (the SAH's, in units of one node's eight-box test): a ray
// that meets a node's entering volume (its slot in the parent: the box, or
// box ∩ filter volume) of area a costs, with kind K chosen at the node,
//
//   F(node, a) = a (1 + c_K) / a_root + sum over children k of F(k, area_K(k)),
//   F(leaf, a) = a c_block / a_root,
//
// where area_K(k) is the area of child k's box ∩ its kind-K volume (its
// box where the kind does not cut it), c_K its filter's cost (0 for boxes
// alone), and area ratios are the probability that a ray meeting one
// convex set meets another inside it (Cauchy's formula, the SAH's
// assumption). Each node's cost is the minimum over kinds, a function of
// its entering area a (a minimum of lines); it is tabulated bottom-up at
// the four areas the parent can give it and chosen top-down from the
// root's box.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "rtcl/accel/bvh.hpp"
#include "rtcl/accel/bvh_child_volumes.hpp"
#include "rtcl/layouts.hpp"

namespace rtcl {

// Relative test costs, in units of one node's eight-box float8 slab test.
// The defaults are the kernel-time ratios of the tests on PoCL CPU devices,
// rounded (bench/volume_cost_bench.cpp, volume_cost/*, measures them on a
// device; docs/benchmarks.md); other devices may call for other values.
struct VolumeCosts {
  float sphere = 1.3f;  // the eight-sphere filter of one node
  float kdop = 1.3f;    // the eight 14-DOP diagonal-slab filter
  float obb = 2.0f;     // the eight-OBB filter
  float block = 8.0f;   // one leaf block (eight triangle tests in float8)
};

struct BvhVolumeFilters {
  std::vector<rtcl_i32> filter_of;  // per node: RTCL_FILTER_REF(kind, record) or RTCL_FILTER_NONE
  std::vector<Bvh8Spheres> spheres;
  std::vector<Bvh8Kdop> kdops;
  std::vector<Bvh8Obb> obbs;
  std::size_t lanes[kFilterKinds] = {};  // per kind: children with a volume, over the chosen records
  double aabb_cost = 0.0;    // expected cost of a ray meeting the root's box, boxes only
  double chosen_cost = 0.0;  // the same with the chosen filters

  bool empty() const { return spheres.empty() && kdops.empty() && obbs.empty(); }
  std::size_t device_bytes() const;
};

// Chooses the filters for `bvh` (flatten_bvh8's output: children after
// their parents). Children holding sphere primitives keep their box alone.
// Throws Error naming `source` for costs that are negative or not finite.
BvhVolumeFilters choose_volume_filters(const Bvh8& bvh, const VolumeCosts& costs, const std::string& source);

}  // namespace rtcl
