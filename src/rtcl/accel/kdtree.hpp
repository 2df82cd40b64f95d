// SAH kd-tree (Havran 2000; Wald & Havran 2006, "On building fast kd-trees
// for ray tracing, and on doing that in O(N log N)"): the BSP's nodes with
// the split plane placed freely, chosen by the surface area heuristic at
// bin boundaries (min-max binning) or over the sorted boundary events of
// the node's primitives (KdTreeConfig::exact_below), whose bounds are those
// of the triangles clipped to the node box ("perfect splits"). Same
// nodes and traversal as the BSP (kdtree_nodes.hpp, kernels/accel/kdtree.cl).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "rtcl/accel/kdtree_nodes.hpp"
#include "rtcl/accel/structure_kernels.hpp"

namespace rtcl {

struct KdTreeConfig {
  // Deepest leaf, in splits (<= kKdMaxDepth); 0 = auto: round(8 + 1.3
  // log2 N) for N stored primitives (pbrt's rule), at most kKdMaxDepth.
  int depth = 0;
  // SAH costs (Wald & Havran 2006, section 4.1): a split of a node with
  // surface area SA into children L, R costs
  //   traversal_cost + intersection_cost * (SA_L / SA * N_L + SA_R / SA * N_R),
  // times (1 - empty_bonus) when one side is empty; a leaf costs
  // intersection_cost * N, and a node whose best split costs more is a leaf.
  // Only the ratio of the two costs matters (Mitsuba uses 15 and 20). The
  // defaults (batch 4, 30) are the fastest to build among the settings
  // that trace best on the shared meshes with the binned build (the sweep:
  // docs/benchmarks.md).
  double traversal_cost = 30.0;
  double intersection_cost = 20.0;
  // The empty-space bonus (Wald & Havran's 0.8 factor = 0.2; range: the
  // `empty` option, kdtree_structure()):
  // favours splits that cut off empty space, which the interval traversal
  // skips for the price of one node.
  double empty_bonus = 0.2;
  // Primitives one intersection test covers in the cost model, 1..8: 1 is
  // the classic SAH (cost per primitive); the kernel tests a leaf's
  // contiguous reference lanes in runs of 8 float8 lanes, where 1 and 8
  // triangles cost the same, so 8 models the tests alone: larger leaves, a
  // shallower tree, fewer references, a faster build. 4 with ct = 30 traces
  // faster than 8 with ct = 15 at the same build time.
  unsigned batch = 4;
  // Subtrees of at most this many references are built by the exact
  // sweep over sorted events (Wald & Havran 2006, O(N log N)); larger
  // nodes are split by the same SAH at up to 64 bin boundaries per axis
  // (min-max binning: linear, no sorting). 0: binned throughout (the
  // default: the faster build, and its trees trace as fast or faster on
  // the shared meshes); 2^30: exact throughout.
  std::size_t exact_below = 0;
  // Host threads (0 = hardware concurrency): the subtrees the binned levels
  // queue, the exact build's large subtrees, and the fused nodes beside the
  // reference lanes.
  unsigned thread_count = 0;
  // The largest buffer the device can allocate (0: no limit).
  std::size_t max_alloc_bytes = 0;
  // Occlusion with the single-ray kernel: consecutive rays per work-item,
  // each tested first against the leaf that blocked the previous one; 1 =
  // no such test, 0 = by device (occluder_run_for, accel.hpp).
  std::uint32_t occluder_run = 0;
};

// The depth the build uses for `primitives` stored primitives.
int kdtree_depth(const KdTreeConfig& config, std::size_t primitives);

// Builds over the stored primitives of validated geometry. The config's
// options hold values in the ranges kdtree_structure() declares (make_accel
// checks them there, once). Throws Error for a tree too large for the
// device.
KdTree build_kdtree(const Geometry& geometry, const KdTreeConfig& config = {});

// Its registry entries: depth, ct (traversal_cost), ci (intersection_cost),
// empty (empty_bonus), batch. "kdtree" traces Coherence::coherent calls on
// CPU devices in packets of 8 rays (accel/kdtree_packet.cl) and the others
// one ray per work-item (accel/kdtree.cl; packets_for_coherent_calls);
// "kdtree-packet", the same tree, always in packets (for measuring).
const StructureSpec& kdtree_structure();
const StructureSpec& kdtree_packet_structure();

std::unique_ptr<Accel> make_kdtree_accel(const Device& device, const Geometry& geometry, const AccelConfig& config);
std::unique_ptr<Accel> make_kdtree_packet_accel(const Device& device, const Geometry& geometry,
                                                const AccelConfig& config);

// Builds and uploads as structure `name`, traced by `traversal`;
// stats().build_ms covers build_kdtree.
std::unique_ptr<Accel> make_kdtree(const Device& device, const Geometry& geometry, const KdTreeConfig& config = {},
                                   const AccelConfig& accel_config = {}, const std::string& name = "kdtree",
                                   KdTraversal traversal = KdTraversal::by_coherence);

}  // namespace rtcl
