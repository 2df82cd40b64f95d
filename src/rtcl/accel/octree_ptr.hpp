// Pointer octrees (lecture, 八叉树的子节点寻址: "each inner node holds eight
// pointers to its children"), walked top-down in kernels/accel/octree_ptr.cl,
// children in the order the ray crosses them (the parametric method of
// Revelles, Urena & Lastra 2000, with split planes anywhere in the node).
// Two structures use it: octree-ptr (the code octree's tree: the cube, split
// at the centre) and octree-r (src/rtcl/accel/octree_r.cpp).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/accel/structure_kernels.hpp"
#include "rtcl/accel/octree_build.hpp"
#include "rtcl/accel/primitive_blocks.hpp"
#include "rtcl/layouts.hpp"

namespace rtcl {

// The depth a pointer octree may have: its traversal stack holds
// 3 * depth + 1 entries.
constexpr int kOctreePtrMaxDepth = 20;

struct OctreePtrConfig {
  int max_depth = 10;           // levels below the root, 0 .. kOctreePtrMaxDepth
  // k >= 1; 32 is the fastest of 4 .. 64 on primary rays
  // (docs/benchmarks.md).
  std::size_t leaf_size = 32;
  // References per stored primitive the tree may hold (OctreeBuildConfig).
  double ref_budget = 16.0;
  std::size_t max_alloc_bytes = 0;
  // Occlusion: consecutive rays per work-item, each tested first against
  // the leaf that blocked the previous one; 1 = no such test, 0 = by device
  // (occluder_run_for, accel.hpp).
  std::uint32_t occluder_run = 0;
};

// The host image of what the kernel reads (OctreeNode, OctreePtrHeader).
struct OctreePtr {
  OctreePtrHeader header{};
  std::vector<OctreeNode> nodes;    // inner nodes, the root first
  // Per leaf l: its triangle blocks [leaf_begin[2l], leaf_begin[2l + 2])
  // and sphere blocks [leaf_begin[2l + 1], leaf_begin[2l + 3]); 2 * (leaves
  // + 1) entries.
  std::vector<rtcl_u32> leaf_begin;
  PrimitiveBlocks blocks;           // each leaf's own copies (append_leaf_blocks)
  std::vector<BlockBox> block_boxes; // one per triangle block
  std::size_t ref_count = 0;        // primitive copies over all leaves
  std::size_t bytes() const;
};

// The device layout of a built tree over the root box [lower, upper]: inner
// nodes in build order, leaves with primitives numbered in that order, each
// with its primitives copied into blocks of its own (contiguous float8
// rows, as BVH leaves, which trace faster than gathered shared references;
// docs/structures.md), empty leaves RTCL_CHILD_EMPTY.
OctreePtr flatten_octree_ptr(const Geometry& geometry, OctreeBuild&& tree, const std::array<float, 3>& lower,
                             const std::array<float, 3>& upper);

// The centre-split octree over the cube (what `octree` builds), as pointers.
OctreePtr build_octree_ptr(const Geometry& geometry, const OctreePtrConfig& config = {});

// Uploads a pointer octree as the structure `name`; stats.build_ms is the
// caller's; occluder_run as OctreePtrConfig's.
std::unique_ptr<Accel> make_octree_ptr_from(const Device& device, const Geometry& geometry, std::string name,
                                            const OctreePtr& tree, std::uint32_t occluder_run, AccelStats stats,
                                            const AccelConfig& config);

const StructureSpec& octree_ptr_structure();

std::unique_ptr<Accel> make_octree_ptr_accel(const Device& device, const Geometry& geometry,
                                             const AccelConfig& config);

std::unique_ptr<Accel> make_octree_ptr(const Device& device, const Geometry& geometry,
                                       const OctreePtrConfig& config = {}, const AccelConfig& accel_config = {});

}  // namespace rtcl
