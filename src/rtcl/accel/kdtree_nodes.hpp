// What the BSP (bsp.cpp) and the kd-tree (kdtree.cpp) share: the node format
// (KdNode, kernels/shared/layouts.h), the traversal kernel
// (kernels/accel/kdtree.cl, the lecture's RayTreeIntersect), and the steps
// around a build: the root box, primitives clipped to node boxes, the build
// tree, its checked flattening into the device layout and the upload. The
// two builders differ only in where they split (bsp: the middle, axis by
// depth; kdtree: the surface area heuristic).
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/accel/structure_kernels.hpp"
#include "rtcl/accel/primitive_blocks.hpp"
#include "rtcl/layouts.hpp"

namespace rtcl {

// The traversal stack's size (-DRTCL_KD_STACK) and so the deepest tree the
// kernel can walk: a leaf at depth D (D inner nodes above it) is reached
// with at most D entries on the stack (kernels/accel/kdtree.cl). Every
// builder's depth option is bounded by it.
constexpr int kKdMaxDepth = 64;

// The host image of what the kernel reads.
struct KdTree {
  KdHeader header{};
  std::vector<KdNode> nodes;      // depth-first, root first
  std::vector<Bvh8Node> fused;    // up to eight cells per node (kdtree_fused.hpp)
  std::vector<rtcl_i32> refs;     // leaf reference lists
  // Reference lanes (KdNode): 9 rows of header.lane_stride floats, and the
  // primitive id of each position; what the kernel tests triangles from.
  std::vector<float> lanes;
  std::vector<rtcl_i32> lane_prims;
  // Stored primitives in id order (in_order_blocks); only the sphere
  // blocks go to the device (the triangles are in the lanes).
  PrimitiveBlocks blocks;
  std::uint32_t depth = 0;        // inner nodes on the longest root-to-leaf path
  std::size_t leaf_count = 0;
  std::size_t bytes() const;      // everything the device holds
  // References per stored triangle (a triangle in two leaves counts twice).
  double references_per_primitive() const;
};

// References per stored primitive a build may list in all (a subtree's
// share of them is its reference budget, split between the children in
// proportion to their counts; a node that cannot split within its share
// is a leaf). Well-behaved scenes stay far below it (a few references per
// primitive); it bounds the growth where every split keeps most primitives on
// both sides, which is exponential in the depth: a fan of thin triangles
// around one vertex, whose neighbourhood every node around the vertex
// lists in full.
constexpr double kKdReferenceBudget = 12.0;

// The stored primitives as a builder sees them: index i < triangle_count is
// triangle reference i (geometry.triangles[ids[i]]), the others spheres
// (reference ~(i - triangle_count)). Node boxes are widened by `widen`
// (64 float ulps of the scene's magnitude, as the grid's cells) before a
// primitive is clipped to them, so that one touching or nearly touching a
// split plane is listed on both sides: that covers the rounding of the
// kernel's plane distances and hit points.
struct KdPrimitives {
  const Geometry* geometry = nullptr;
  std::vector<std::uint32_t> ids;
  std::size_t triangle_count = 0;
  glm::dvec3 lower{0.0}, upper{0.0};  // the root box (KdTree::header's floats)
  double widen = 0.0;
  std::size_t size() const { return ids.size(); }
  // The bounds of primitive i within the widened box [lower, upper]: the
  // triangle clipped to it (perfect splits), the sphere's box cut to it;
  // false when the primitive does not reach the box.
  bool clip(std::uint32_t i, const glm::dvec3& lower, const glm::dvec3& upper, glm::dvec3* clipped_lower,
            glm::dvec3* clipped_upper) const;
  // Its bounds without clipping.
  void bounds(std::uint32_t i, glm::dvec3* lower, glm::dvec3* upper) const;
  // clip() to both children of [lower, upper] split at p on `axis` at once
  // (clip_triangle_split: the parent clip shared): bounds[0] below, [1]
  // above; reaches[k] false when the primitive does not reach child k.
  void clip_split(std::uint32_t i, const glm::dvec3& lower, const glm::dvec3& upper, int axis, double p,
                  std::array<bool, 2>* reaches, std::array<glm::dvec3, 2>* clipped_lower,
                  std::array<glm::dvec3, 2>* clipped_upper) const;
};

// x rounded to a float towards -inf (down) or +inf: float bounds that
// enclose double ones. Inline: the builds round six bounds per clip.
inline float kd_round_float(double x, bool down) {
  float f = static_cast<float>(x);
  if (down && f > x) return std::nextafter(f, -std::numeric_limits<float>::infinity());
  if (!down && f < x) return std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

// The stored primitives of validated geometry and the root box: the scene
// box padded by 16 float ulps of its magnitude and rounded outwards to
// float. `structure` names the builder in errors: the primitive blocks
// must fit in max_alloc_bytes (0: no limit), checked before any work.
KdPrimitives kd_primitives(const Geometry& geometry, const std::string& structure, std::size_t max_alloc_bytes);

// A float box; empty() has lower +inf, upper -inf (a cell no ray enters).
struct KdBox {
  float lower[3], upper[3];
  static KdBox empty() {
    const float inf = std::numeric_limits<float>::infinity();
    return {{inf, inf, inf}, {-inf, -inf, -inf}};
  }
  void grow(const KdBox& b) {
    for (int a = 0; a < 3; ++a) {
      lower[a] = std::min(lower[a], b.lower[a]);
      upper[a] = std::max(upper[a], b.upper[a]);
    }
  }
};

// A node of the build tree: inner (axis 0..2) with both children, or a leaf
// (axis -1) listing primitive indices of KdPrimitives. A builder that knows
// the bounds of a leaf's primitives clipped to its (widened) cell, rounded
// outwards, gives their union as `content` (has_content); flatten_kd_tree
// clips them again otherwise.
struct KdBuildNode {
  int axis = -1;
  float split = 0.0f;
  std::unique_ptr<KdBuildNode> below, above;
  std::vector<std::uint32_t> prims;
  bool has_content = false;
  KdBox content = KdBox::empty();
};

// Flattens the build tree into the device layout. Throws Error naming the
// structure and its options (`option`, e.g. "depth=20") when the tree is
// deeper than kKdMaxDepth, when a node or reference index needs more than
// 30 bits or the reference lanes more than 2^31 floats, or when nodes,
// references or the reference lanes exceed max_alloc_bytes (0: none).
// With threads > 1 the fused nodes are built on a second thread.
KdTree flatten_kd_tree(const KdPrimitives& prims, const KdBuildNode& root, const std::string& structure,
                       const std::string& option, std::size_t max_alloc_bytes, unsigned threads = 1);

// Spare host threads for parallel subtree builds (as the BVH's builder).
class KdThreads {
 public:
  explicit KdThreads(int spare) : spare_(spare) {}
  bool try_take();
  void give_back() { spare_.fetch_add(1); }

 private:
  std::atomic<int> spare_;
};

// Which kernel traces a call: accel/kdtree.cl (one ray per work-item) or
// accel/kdtree_packet.cl (packets of 8 rays).
enum class KdTraversal {
  single,        // always one ray per work-item
  by_coherence,  // packets for Coherence::coherent calls on CPU devices (packets_for_coherent_calls), else single rays
  packet,        // always packets (for measuring)
};

// Uploads the tree as structure `name` (the kernels of accel/kdtree.cl and
// accel/kdtree_packet.cl, chosen by `traversal`). occluder_run: the
// structure's `occluder_run` option (occluder_run_for, accel.hpp), for the
// single-ray kernel's occlusion queries.
std::unique_ptr<Accel> make_kd_accel(const Device& device, const Geometry& geometry, const std::string& name,
                                     const KdTree& tree, AccelStats stats, const AccelConfig& config,
                                     KdTraversal traversal = KdTraversal::single, std::uint32_t occluder_run = 0);

// Validates the geometry, builds with build(max_alloc_bytes), the device's
// largest buffer, and uploads as `name`; stats().build_ms covers the
// validation and the build.
std::unique_ptr<Accel> build_kd_accel(const Device& device, const Geometry& geometry, const std::string& name,
                                      const std::function<KdTree(std::size_t max_alloc_bytes)>& build,
                                      const AccelConfig& config, KdTraversal traversal = KdTraversal::single,
                                      std::uint32_t occluder_run = 0);

}  // namespace rtcl
