// The single-ray traversal's nodes (Bvh8Node records, kernels/shared/
// layouts.h, after KdNode): a flattened BSP / kd-tree (KdNode array) cut
// into subtrees of up to eight cells, the cells in a node's lanes, so that
// one step of kernels/accel/kdtree.cl finds the ray's [min, max] in eight
// cells at once (a float8 slab test of their boxes).
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>
#include <limits>
#include <vector>

#include "rtcl/accel/kdtree_nodes.hpp"

namespace rtcl {

// The traversal stack of the fused nodes (-DRTCL_KD_CELL_STACK). Every
// fused node below the root starts at an inner kd node and takes at least
// its two children's levels, so a tree of depth D <= kKdMaxDepth has at
// most max(1, D) fused levels. A step pushes at most the eight cells the
// ray enters and the walk then pops one of them, so while a node at fused
// depth f is walked each of its f - 1 fused ancestors keeps at most 7
// entries on the stack, and after its own pushes the stack holds at most
// 7 (f - 1) + 8 = 7 f + 1.
constexpr int kKdCellStack = 7 * kKdMaxDepth + 1;

// The fused nodes of `nodes` (depth-first, root first; the root box from
// `header`); leaves stay in `nodes` and are referenced as ~index. A leaf's
// lane holds leaf_bounds(leaf index, its kd cell): the box a hit in it can
// lie in (what its primitives cover within the cell); a deeper subtree's
// lane the union of its node's lanes.
std::vector<Bvh8Node> fuse_kd_nodes(const std::vector<KdNode>& nodes, const KdHeader& header,
                                    const std::function<KdBox(std::size_t leaf, const KdBox& cell)>& leaf_bounds);

}  // namespace rtcl
