// Axis-aligned BSP tree exactly as the lecture defines it (空间二分树,
// "Axis-aligned BSP 树"): every node is split at the middle of its extent,
// the axis rotating x -> y -> z with depth; a node becomes a leaf at the
// depth limit or when it holds few enough primitives. A primitive reaching
// both halves is listed in both (decided by clipping the triangle to each
// child box). Same nodes and traversal as the kd-tree (kdtree_nodes.hpp,
// kernels/accel/kdtree.cl).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "rtcl/accel/kdtree_nodes.hpp"
#include "rtcl/accel/structure_kernels.hpp"

namespace rtcl {

struct BspConfig {
  // Deepest leaf, in splits (<= kKdMaxDepth); 0 = auto:
  // round(log2(N)) + 6 for N stored primitives. Deeper trees cut clusters
  // finer at the price of more straddling references and nodes; the + 6
  // is where deeper trees stop paying on the shared meshes (the depth
  // sweep: docs/benchmarks.md).
  int depth = 0;
  // A node with at most this many primitives becomes a leaf (>= 1). A leaf
  // is tested in batches of 8, so fewer than 8 saves little testing and
  // costs nodes.
  int leaf_size = 6;
  // Host threads (0 = hardware concurrency) for subtrees of nodes with at
  // least 4096 primitives.
  unsigned thread_count = 0;
  // The largest buffer the device can allocate (0: no limit).
  std::size_t max_alloc_bytes = 0;
  // Occlusion with the single-ray kernel: consecutive rays per work-item,
  // each tested first against the leaf that blocked the previous one; 1 =
  // no such test, 0 = by device (occluder_run_for, accel.hpp).
  std::uint32_t occluder_run = 0;
};

// The depth the build uses for `primitives` stored primitives.
int bsp_depth(const BspConfig& config, std::size_t primitives);

// Builds over the stored primitives of validated geometry. Throws Error
// naming the option for a bad config or a tree too large for the device.
KdTree build_bsp(const Geometry& geometry, const BspConfig& config = {});

// Its registry entry: depth (BspConfig::depth, 0 = auto) and leaf
// (BspConfig::leaf_size).
const StructureSpec& bsp_structure();

std::unique_ptr<Accel> make_bsp_accel(const Device& device, const Geometry& geometry, const AccelConfig& config);

// Builds and uploads; stats().build_ms covers build_bsp.
std::unique_ptr<Accel> make_bsp(const Device& device, const Geometry& geometry, const BspConfig& config = {},
                                const AccelConfig& accel_config = {});

}  // namespace rtcl
