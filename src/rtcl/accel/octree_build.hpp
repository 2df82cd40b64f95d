// Top-down octree subdivision shared by the three octrees (lecture, 八叉树:
// "the scene in an axis-aligned cube, subdivided top-down into 2x2x2
// children until a termination condition holds; primitives are stored only
// in leaves, a primitive overlapping several leaves listed in each"). The
// split planes come from a rule: the cube's centre for octree and
// octree-ptr (src/rtcl/accel/octree.cpp), a cost heuristic for octree-r
// (src/rtcl/accel/octree_r.cpp). The addressing (codes or pointers) is the
// flatten step's business.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/accel.hpp"
#include "rtcl/accel/primitive_blocks.hpp"
#include "rtcl/layouts.hpp"
#include "rtcl/geometry.hpp"

namespace rtcl {

struct OctreeBuildConfig {
  std::string structure = "octree";  // named in errors
  // Maximum depth N: the root is level 0, a node at level N is a leaf.
  int max_depth = 8;
  // A node with at most this many primitives is a leaf (k >= 1).
  std::size_t leaf_size = 8;
  // When > 0, a split is kept only when it lowers the estimated cost of a
  // ray meeting the node, in units of one primitive test: split_cost (the
  // traversal step) + sum over the children of area(child) / area(node) *
  // primitives(child) < primitives(node) (Octree-R's surface-area model;
  // it stops where no plane separates the primitives). 0: no cost test.
  double split_cost = 0.0;
  // References the whole tree may hold per stored primitive (>= 1): nodes
  // are split breadth first, and a split that would take the total past
  // the budget is not made (the node stays a leaf). Bounds memory and build
  // time where depth and leaf size alone do not: surfaces that meet along a
  // line or at a point (a fan of slivers around one vertex) hold more than
  // leaf_size primitives in every cell down to the maximum depth.
  double ref_budget = 16.0;
  // The largest buffer the device can allocate (0: no limit); the build
  // stops with an Error as soon as the references or nodes exceed it.
  std::size_t max_alloc_bytes = 0;
};

// A node of the build. Its box (lower, upper) is in float, each coordinate
// exactly the value the kernel computes for it; children split it at
// split[a] on every axis.
struct OctreeBuildNode {
  std::array<float, 3> lower{}, upper{}, split{};
  int level = 0;
  std::array<std::uint32_t, 3> lattice{};  // lower corner in lattice units (centre splits of a cube)
  std::uint64_t digits = 0;                // q1 .. q_level, 3 bits each, q1 the highest
  std::array<std::int32_t, 8> child{{-1, -1, -1, -1, -1, -1, -1, -1}};  // node indices; all -1 in a leaf
  std::vector<rtcl_i32> refs;              // leaves only: triangles k >= 0 then spheres ~j (grid encoding)
  bool leaf() const { return child[0] < 0; }
};

// The bounds of every stored primitive, by reference: triangle k of
// stored_primitives at [k], sphere j at [triangle_count + j].
struct PrimitiveBounds {
  std::vector<glm::dvec3> lower, upper;
  std::size_t triangle_count = 0;
  std::size_t index(rtcl_i32 ref) const { return ref >= 0 ? std::size_t(ref) : triangle_count + std::size_t(~ref); }
};

struct OctreeBuild {
  std::vector<OctreeBuildNode> nodes;  // nodes[0] is the root; children after their parents
  std::vector<std::uint32_t> ids;      // stored_primitives: reference k is triangle ids[k]
  PrimitiveBlocks blocks;              // in_order_blocks: what references index
  std::size_t ref_count = 0;           // references over all leaves
  std::size_t filled_leaves = 0;       // leaves with at least one reference
  int depth = 0;                       // deepest level reached
};

// Chooses the split planes of `node`, an inner node to be, holding `refs`.
using OctreeSplitRule = std::function<std::array<float, 3>(const OctreeBuildNode& node,
                                                           const std::vector<rtcl_i32>& refs,
                                                           const PrimitiveBounds& bounds)>;

// The widening of every node box for the overlap tests (64 float ulps of
// the scene's magnitude, as the grid's): covers the rounding of the
// kernels' planes, slab distances and hit points, so that a primitive
// touching or nearly touching a boundary is listed on both sides.
double octree_widening(const Geometry& geometry);
// The padding of the scene box before the root box is rounded outwards to
// float (16 float ulps of the magnitude, as the grid's).
double octree_padding(const Geometry& geometry);
// The largest coordinate magnitude of the scene box.
double scene_magnitude(const Geometry& geometry);

// Validates config (Error "STRUCTURE: depth ..." / "leaf_size ...") and
// subdivides the root box [lower, upper] over the stored primitives of
// validated geometry. A node becomes a leaf at level max_depth, with at
// most leaf_size primitives, when no child would hold fewer primitives
// than it (no progress), when the split does not pay (split_cost), or when
// it would exceed the reference budget (ref_budget); a primitive is listed in every child whose
// widened closed box it meets (exact triangle/box and sphere/box tests).
// `max_depth_limit` is what the structure's addressing can hold.
OctreeBuild build_octree_nodes(const Geometry& geometry, const std::array<float, 3>& lower,
                               const std::array<float, 3>& upper, const OctreeBuildConfig& config,
                               int max_depth_limit, const OctreeSplitRule& rule);

// Appends the primitives of leaf `node` (its refs, ascending: triangles
// then spheres; `ids` = OctreeBuild::ids) to `blocks` as blocks of its own,
// eight to a block, ids ascending (so that a tie between two of its
// primitives goes to the lower id, as in brute force), and then the new
// ends of the triangle and sphere block arrays to `leaf_begin` (the pair
// layout of OctreeHeader / OctreeNode leaves). Each triangle block gets its
// BlockBox in `boxes` (the node's cell widened by `widening`,
// octree_widening).
void append_leaf_blocks(const Geometry& geometry, const std::vector<std::uint32_t>& ids,
                        const OctreeBuildNode& node, double widening, PrimitiveBlocks& blocks,
                        std::vector<BlockBox>& boxes, std::vector<rtcl_u32>& leaf_begin);

// The box of leaf `node`'s spheres clipped to its cell widened by
// `widening` (empty, lower +inf and upper -inf, when it has none), and the
// union of two boxes.
BlockBox leaf_sphere_box(const Geometry& geometry, const OctreeBuildNode& node, double widening);
void grow_box(BlockBox& box, const BlockBox& other);

// The boxes on the device; a one-box placeholder where there is none, so
// that the kernel signature never changes.
cl::Buffer upload_block_boxes(const Device& device, const std::vector<BlockBox>& boxes);

// The options every octree declares (depth, leaf_size, ref_budget), with
// these defaults and depth range [0, max_depth], then `extra`.
std::vector<OptionSpec> octree_options(int max_depth, int depth, std::size_t leaf_size, double ref_budget,
                                       std::vector<OptionSpec> extra = {});
// Reads them (resolved options) into `config`'s max_depth, leaf_size and
// ref_budget.
template <class Config>
void read_octree_options(const AccelOptions& o, Config* config) {
  config->max_depth = static_cast<int>(o.integer("depth"));
  config->leaf_size = static_cast<std::size_t>(o.integer("leaf_size"));
  config->ref_budget = o.real("ref_budget");
  config->occluder_run = static_cast<std::uint32_t>(o.integer("occluder_run"));
}
// The common part of a structure's config, for build_octree_nodes.
template <class Config>
OctreeBuildConfig octree_build_config(const Config& config, std::string structure) {
  OctreeBuildConfig build;
  build.structure = std::move(structure);
  build.max_depth = config.max_depth;
  build.leaf_size = config.leaf_size;
  build.ref_budget = config.ref_budget;
  build.max_alloc_bytes = config.max_alloc_bytes;
  return build;
}

// Checks the common options before any work: depth in [0, max_depth_limit]
// and leaf_size >= 1, else Error naming the structure and the option.
void check_octree_config(const OctreeBuildConfig& config, int max_depth_limit);

// What every octree factory does around its builder: validates geometry,
// limits config.max_alloc_bytes to the device's largest buffer when unset,
// runs build(geometry, config) and fills stats->build_ms (validation and
// build) and the primitive counts.
template <class Config, class Build>
auto timed_octree_build(const Device& device, const Geometry& geometry, Config config, const Build& build,
                        AccelStats* stats) {
  auto start = std::chrono::steady_clock::now();
  GeometryReport report = validate(geometry);
  if (!config.max_alloc_bytes) config.max_alloc_bytes = device.info().max_alloc_bytes;
  auto tree = build(geometry, config);
  stats->build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  stats->primitive_count = geometry.primitive_count() - report.zero_area_triangles;
  stats->zero_area_skipped = report.zero_area_triangles;
  stats->bounds = geometry.bounds();
  return tree;
}

}  // namespace rtcl
