// Octree addressed by node codes (lecture: 八叉树, 空间八叉树剖分技术,
// 光线跟踪过程): the scene in its smallest axis-aligned cube, split at the
// centre top-down (src/rtcl/accel/octree_build.cpp); the leaves that hold
// primitives kept as a table sorted by code, child q of code c being c·8 + q
// (one hexadecimal digit per level, unused levels F), walked in
// kernels/accel/octree.cl by locating each point's code in the table and
// stepping through cell exit points in integer lattice coordinates.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/accel/structure_kernels.hpp"
#include "rtcl/accel/octree_build.hpp"
#include "rtcl/accel/primitive_blocks.hpp"
#include "rtcl/layouts.hpp"

namespace rtcl {

struct OctreeConfig {
  // Maximum depth N (lattice 2^N per axis), 0 .. RTCL_OCTREE_MAX_DEPTH
  // (16 hexadecimal digits fill the 64-bit code). The defaults' sweep:
  // docs/benchmarks.md.
  int max_depth = 10;
  // Primitives a node may hold and still be a leaf (k >= 1). 32 traces
  // faster than smaller leaves (docs/benchmarks.md).
  std::size_t leaf_size = 32;
  // References per stored primitive the tree may hold (OctreeBuildConfig).
  double ref_budget = 16.0;
  // Index the table by the first digits of a code (bucket_begin, about one
  // bucket per two leaves) before the binary search; false: binary search
  // over the whole table, which is slower.
  bool buckets = true;
  // The largest buffer the device can allocate (0: no limit).
  std::size_t max_alloc_bytes = 0;
  // Occlusion: consecutive rays per work-item, each tested first against
  // the leaf that blocked the previous one; 1 = no such test, 0 = by device
  // (occluder_run_for, accel.hpp).
  std::uint32_t occluder_run = 0;
};

// The host image of what the kernel reads (OctreeHeader contract).
struct Octree {
  OctreeHeader header{};
  std::vector<std::uint64_t> codes;       // leaves with primitives, ascending
  std::vector<rtcl_u32> leaf_begin;       // 2 * (codes.size() + 1) block offsets (OctreeHeader)
  std::vector<rtcl_u32> bucket_begin;     // 8^top_digits + 1 table offsets
  PrimitiveBlocks blocks;                 // each leaf's own blocks (append_leaf_blocks)
  std::vector<BlockBox> block_boxes;      // one per triangle block
  std::size_t ref_count = 0;              // primitive copies over all leaves
  std::size_t node_count = 0;             // inner nodes and leaves, empty ones too
  std::size_t bytes() const;              // everything the device holds
};

// The cube of depth n over the padded box of validated geometry: lower
// corner and lattice unit (the planes lower + (float)n * cell contain it).
OctreeHeader octree_cube(const Geometry& geometry, int depth);

// The cube's upper corner: lattice plane 2^depth on each axis.
std::array<float, 3> octree_cube_upper(const OctreeHeader& cube);

// Splits a node of the cube at its centre, lattice plane lattice + half of
// its side, as the code kernel's property 2 computes it (octree and
// octree-ptr: the same tree, addressed two ways).
OctreeSplitRule octree_centre_rule(const OctreeHeader& cube);

// Property 1: the code of the unit cell at lattice point (x, y, z) of a
// depth-n lattice (each coordinate < 2^n): digit l (1-based) is bit n - l of
// x + 2 * that of y + 4 * that of z.
std::uint64_t octree_point_code(const std::array<std::uint32_t, 3>& point, int depth);
// The code of the level-`level` node holding that point: its first `level`
// digits, then F.
std::uint64_t octree_node_code(std::uint64_t point_code, int level, int depth);
// Property 2: the lower corner (lattice units) of the node of `code` at
// `level`: its digits' bits, zeros below.
std::array<std::uint32_t, 3> octree_lower_corner(std::uint64_t code, int level, int depth);

// Builds the code octree over validated geometry; Error naming the option
// for a bad config or an octree too large for config.max_alloc_bytes.
Octree build_octree(const Geometry& geometry, const OctreeConfig& config = {});

// Its registry entry: depth, leaf_size, buckets.
const StructureSpec& octree_structure();

std::unique_ptr<Accel> make_octree_accel(const Device& device, const Geometry& geometry, const AccelConfig& config);

// Builds and uploads; stats().build_ms covers build_octree.
std::unique_ptr<Accel> make_octree(const Device& device, const Geometry& geometry, const OctreeConfig& config = {},
                                   const AccelConfig& accel_config = {});

}  // namespace rtcl
