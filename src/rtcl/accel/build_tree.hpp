// The binary build tree every BVH builder returns and the 8-wide flatten
// step consumes (src/rtcl/accel/bvh.hpp). Builders are functions of bounds:
// they see primitive boxes and ids, never triangles or spheres.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "rtcl/aabb.hpp"
#include "rtcl/error.hpp"

namespace rtcl {

// One node. A leaf holds prims[first .. first + count) of its BuildTree
// (1 <= count <= RTCL_BLOCK_WIDTH); an inner node (count == 0) has two
// children. bounds contains the boxes of every primitive below the node.
struct BuildNode {
  Aabb bounds;
  std::uint32_t child[2] = {0, 0};  // inner node: indices into BuildTree::nodes
  std::uint32_t first = 0;          // leaf: index into BuildTree::prims
  std::uint32_t count = 0;          // leaf: primitive count; 0 for an inner node

  bool is_leaf() const { return count > 0; }
};

struct BuildTree {
  std::vector<BuildNode> nodes;      // nodes[0] is the root; empty for no primitive
  std::vector<std::uint32_t> prims;  // primitive ids (the caller's), leaves' ranges

  bool empty() const { return nodes.empty(); }
  // Longest root-to-leaf path in nodes (a lone leaf root has depth 1).
  std::uint32_t depth() const;
};

// A tree whose root has `a` and `b` as its two subtrees (either may be empty:
// then the other is returned unchanged).
BuildTree join(BuildTree a, BuildTree b);

// Throws Error (naming `builder`) unless bounds and ids have the same length
// and every box is finite with lower <= upper.
void check_builder_input(std::span<const Aabb> bounds, std::span<const std::uint32_t> ids, const char* builder);
// The first half of check_builder_input: the lengths alone (a builder that
// tests the boxes in its own pass over them, with builder_box_error).
void check_builder_sizes(std::span<const Aabb> bounds, std::span<const std::uint32_t> ids, const char* builder);
// check_builder_input's error for the box of primitive `id`.
Error builder_box_error(std::uint32_t id, const char* builder);

// "" when the tree is well formed for these inputs: every id of `ids` sits in
// exactly one leaf, every leaf has 1..max_leaf primitives, every node is
// reached exactly once from the root, and every node's bounds contain its
// children's and its primitives' boxes (bounds[i] is the box of ids[i]).
// Otherwise the first problem found.
std::string check(const BuildTree& tree, std::span<const Aabb> bounds, std::span<const std::uint32_t> ids,
                  std::uint32_t max_leaf);

}  // namespace rtcl
