// The node format and traversal shared by bsp and kdtree
// (src/rtcl/accel/kdtree_nodes.cpp, kernels/accel/kdtree.cl): a tree of the
// deepest depth the stack holds, walked so that every level pushes.
#include <gtest/gtest.h>

#include "rtcl/accel/kdtree_fused.hpp"
#include "rtcl/accel/kdtree_nodes.hpp"
#include "rtcl/error.hpp"
#include "support/fixtures.hpp"
#include "support/kd_support.hpp"

namespace rtcl::test {
namespace {

// A chain of kKdMaxDepth inner nodes splitting x at 1 - k / 65 (each inside
// the one before): a ray along +x from x < 0 crosses every plane, so every
// node pushes its far child and the packet walk's stack fills to exactly
// kKdMaxDepth (the single-ray walk's fused nodes hold seven of the chain's
// leaves and its next node each, and push them all). All leaves list all
// primitives, so every leaf answers as brute force does.
TEST(KdNodes, AChainOfTheDeepestDepthFillsTheStackExactly) {
  Geometry g = random_soup(40, 12);
  KdPrimitives prims = kd_primitives(g, "kd chain", 0);
  std::vector<std::uint32_t> all(prims.size());
  for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
  KdBuildNode root;
  KdBuildNode* node = &root;
  for (int k = 1; k <= kKdMaxDepth; ++k) {
    node->axis = 0;
    node->split = 1.0f - static_cast<float>(k) / 65.0f;
    node->above = std::make_unique<KdBuildNode>();
    node->above->prims = all;
    node->below = std::make_unique<KdBuildNode>();
    node = node->below.get();
  }
  node->prims = all;
  KdTree tree = flatten_kd_tree(prims, root, "kd chain", "", 0);
  ASSERT_EQ(tree.depth, static_cast<std::uint32_t>(kKdMaxDepth));
  std::vector<Ray> rays;
  for (int i = 0; i < 64; ++i) {
    float y = (i % 8 + 0.5f) / 8.0f, z = (i / 8 + 0.5f) / 8.0f;
    rays.push_back({-1.0f, y, z, 1.0f, 0.01f * (i % 3), (i % 2) ? 0.0f : -0.0f, 0.0f, INFINITY});
  }
  std::vector<Ray> planes = split_plane_rays(tree, 13, 300);
  rays.insert(rays.end(), planes.begin(), planes.end());
  for (KdTraversal traversal : {KdTraversal::single, KdTraversal::packet})  // one ray, packets of 8
    for (Precision level : {Precision::robust, Precision::exact}) {
      AccelStats stats;
      auto accel = make_kd_accel(test_device(), g, traversal == KdTraversal::packet ? "kdtree-packet" : "kdtree", tree,
                                 stats, AccelConfig{level, {}}, traversal);
      expect_same_as_brute(*accel, g, rays, level);
    }
  // One level more is refused before any upload.
  KdBuildNode deeper;
  deeper.axis = 0;
  deeper.split = 0.999f;
  deeper.above = std::make_unique<KdBuildNode>();
  deeper.below = std::make_unique<KdBuildNode>(std::move(root));
  EXPECT_THROW(flatten_kd_tree(prims, deeper, "kd chain", "depth=65", 0), Error);
}


// A leaf with all primitives, an empty leaf, or a split into two such.
std::unique_ptr<KdBuildNode> kd_leaf(const std::vector<std::uint32_t>& prims) {
  auto leaf = std::make_unique<KdBuildNode>();
  leaf->prims = prims;
  return leaf;
}
std::unique_ptr<KdBuildNode> kd_split(int axis, float split, std::unique_ptr<KdBuildNode> below,
                                      std::unique_ptr<KdBuildNode> above) {
  auto node = std::make_unique<KdBuildNode>();
  node->axis = axis;
  node->split = split;
  node->below = std::move(below);
  node->above = std::move(above);
  return node;
}

// Midpoint splits of [lower, upper] down to `depth`, the axis by depth;
// every leaf lists `prims`, except that the first leaf above z = 0.5 is empty
// unless *emptied already holds, and a subtree at depth 2 is one leaf.
std::unique_ptr<KdBuildNode> kd_midpoints(const std::vector<std::uint32_t>& prims, glm::vec3 lower, glm::vec3 upper,
                                          int depth, int level, bool* emptied) {
  if (level == depth || (level == 2 && lower.x > 0.4f && lower.y > 0.4f)) {
    if (!*emptied && lower.z >= 0.5f) {
      *emptied = true;
      return kd_leaf({});
    }
    return kd_leaf(prims);
  }
  const int axis = level % 3;
  const float split = 0.5f * (lower[axis] + upper[axis]);
  glm::vec3 below_upper = upper, above_lower = lower;
  below_upper[axis] = split;
  above_lower[axis] = split;
  auto below = kd_midpoints(prims, lower, below_upper, depth, level + 1, emptied);
  auto above = kd_midpoints(prims, above_lower, upper, depth, level + 1, emptied);
  return kd_split(axis, split, std::move(below), std::move(above));
}

// The single-ray kernel walks fused nodes (kdtree_fused.hpp): each lane a
// cell of several kd levels. Every leaf with references is the lane of
// exactly one fused node, empty leaves of none; a lane's box lies within the
// box of the lane that leads to its node; a tree of one leaf is one fused
// node of one lane. Without the empty leaf every leaf lists every
// primitive, so the tree traces as brute force does, with rays along the
// planes and through their crossings.
TEST(KdNodes, FusedNodesHoldEveryLeafWithReferencesOnceWithinTheirParentsBoxes) {
  Geometry g = random_soup(60, 21);
  KdPrimitives prims = kd_primitives(g, "kd fused", 0);
  std::vector<std::uint32_t> all(prims.size());
  for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
  bool emptied = false;
  auto root = kd_midpoints(all, glm::vec3(0.0f), glm::vec3(1.0f), 7, 0, &emptied);
  KdTree tree = flatten_kd_tree(prims, *root, "kd fused", "", 0);
  ASSERT_TRUE(emptied);
  ASSERT_GT(tree.fused.size(), 8u);
  std::vector<int> seen(tree.nodes.size(), 0);
  std::vector<int> parent(tree.fused.size(), -1), parent_lane(tree.fused.size(), -1);
  for (std::size_t i = 0; i < tree.fused.size(); ++i)
    for (int k = 0; k < 8; ++k) {
      const rtcl_i32 c = tree.fused[i].child[k];
      if (c == RTCL_KD_NO_CELL) {
        EXPECT_EQ(tree.fused[i].bounds[0][k], INFINITY);
      } else if (c < 0) {
        ++seen[static_cast<std::size_t>(~c)];
      } else {
        parent[static_cast<std::size_t>(c)] = static_cast<int>(i);
        parent_lane[static_cast<std::size_t>(c)] = k;
      }
    }
  for (std::size_t n = 0; n < tree.nodes.size(); ++n)
    if ((tree.nodes[n].flags & 3u) == RTCL_KD_LEAF) EXPECT_EQ(seen[n], tree.nodes[n].data > 0 ? 1 : 0) << n;
  for (std::size_t i = 1; i < tree.fused.size(); ++i) {
    ASSERT_GE(parent[i], 0);
    const Bvh8Node& up = tree.fused[static_cast<std::size_t>(parent[i])];
    for (int k = 0; k < 8; ++k)
      for (int a = 0; a < 3; ++a)
        if (tree.fused[i].child[k] != RTCL_KD_NO_CELL) {
          EXPECT_GE(tree.fused[i].bounds[a][k], up.bounds[a][parent_lane[i]]);
          EXPECT_LE(tree.fused[i].bounds[3 + a][k], up.bounds[3 + a][parent_lane[i]]);
        }
  }

  bool no_empty = true;
  KdTree full = flatten_kd_tree(prims, *kd_midpoints(all, glm::vec3(0.0f), glm::vec3(1.0f), 7, 0, &no_empty),
                                "kd fused", "", 0);
  KdTree lone = flatten_kd_tree(prims, *kd_leaf(all), "kd fused", "", 0);
  ASSERT_EQ(lone.fused.size(), 1u);
  int lanes = 0;
  for (rtcl_i32 c : lone.fused[0].child) lanes += c == ~0 ? 1 : 0;
  EXPECT_EQ(lanes, 1);

  for (const KdTree* t : {&full, &lone}) {
    std::vector<Ray> rays = random_rays(g, 400, 22);
    std::vector<Ray> planes = split_plane_rays(*t, 23, 400);
    rays.insert(rays.end(), planes.begin(), planes.end());
    for (Precision level : test_precisions()) {
      AccelStats stats;
      auto accel = make_kd_accel(test_device(), g, "kdtree", *t, stats, AccelConfig{level, {}}, KdTraversal::single);
      expect_same_as_brute(*accel, g, rays, level);
    }
  }
}

}  // namespace
}  // namespace rtcl::test
