// The SAH-optimal collapse of a binary BVH into 8-wide nodes and blocks
// (Ylitie, Karras and Laine 2017, "Efficient incoherent ray traversal on GPUs
// through compressed wide BVHs", section 3.1): dynamic programming over the
// binary nodes, bottom up. For every binary node m and budget i (1..8) it
// finds the least surface-area cost of m's subtree laid out as at most i
// children of one wide node: m itself as one child (a wide node of its own,
// or one block when its subtree holds at most 8 primitives of one kind), or
// the budget shared between m's two children. Cost units: one block test =
// 1 per unit of box area, one wide node's test = kCollapseNodeCost.
//
// The greedy collapse (open the child of largest area until eight) leaves
// many wide nodes with two or three children near the leaves; this plan
// fills them: fewer wide nodes and a lower SAH cost.
// flatten_bvh8 follows it below its greedy top levels (bvh.hpp,
// BvhConfig::greedy_levels).
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "rtcl/accel/build_tree.hpp"
#include "rtcl/geometry.hpp"

namespace rtcl {

// A wide node's test against one 8-primitive block test (the SAH builder's
// node_cost default; the plan's node count changes little between 0.25
// and 2).
inline constexpr float kCollapseNodeCost = 0.5f;

class CollapsePlan {
 public:
  // Room for the plan of a tree of `nodes` binary nodes, none planned yet
  // (plan_subtree fills it).
  explicit CollapsePlan(std::size_t nodes = 0) : split_(nodes), wide_(nodes), seen_(nodes) {}

  // Slots for binary node m's children when m's subtree may take `budget`
  // (1..8) children: {left, right}, both >= 1; {0, 0}: m is one child.
  std::pair<int, int> split(std::uint32_t m, int budget) const {
    const std::uint8_t s = split_[m][budget - 1];
    return budget == 1 ? std::pair(0, 0) : std::pair(s & 15, s >> 4);
  }
  // Whether m, as one child, is one block of its subtree's primitives
  // (otherwise a wide node; a binary leaf always is a block).
  bool is_block(std::uint32_t m) const { return split_[m][0] != 0; }
  // m as a wide node: the slots for its two children, {left, right}.
  std::pair<int, int> wide_split(std::uint32_t m) const { return {wide_[m] & 15, wide_[m] >> 4}; }

 private:
  friend void plan_subtree(const BuildTree& tree, const Geometry& geometry, std::uint32_t root, CollapsePlan& plan);
  // Per node: [0] is_block; [i - 1] for budget i >= 2: left | right << 4.
  std::vector<std::array<std::uint8_t, 8>> split_;
  std::vector<std::uint8_t> wide_;  // left | right << 4
  // Nodes planned, each claimed by one plan_subtree call: a node reached
  // twice, in one subtree or in two, is an error, never planned twice.
  std::vector<std::atomic<std::uint8_t>> seen_;
};

// Plans the subtree of binary node `root` of `tree`, whose leaves index
// geometry's primitives (triangles, then spheres), into plan (made for
// tree's nodes). Disjoint subtrees may be planned on several threads at
// once. Throws Error when a child does not exist or a node is reached twice
// (the flatten checks the rest).
void plan_subtree(const BuildTree& tree, const Geometry& geometry, std::uint32_t root, CollapsePlan& plan);

// The plan of the whole tree (plan_subtree from the root).
CollapsePlan plan_collapse(const BuildTree& tree, const Geometry& geometry);

}  // namespace rtcl
