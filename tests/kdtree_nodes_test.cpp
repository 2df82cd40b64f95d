// The node format and traversal shared by bsp and kdtree
// (src/rtcl/accel/kdtree_nodes.cpp, kernels/accel/kdtree.cl): a tree of the
// deepest depth the stack holds, walked so that every level pushes.
#include <gtest/gtest.h>

#include "rtcl/accel/kdtree_nodes.hpp"
#include "rtcl/error.hpp"
#include "support/fixtures.hpp"
#include "support/kd_support.hpp"

namespace rtcl::test {
namespace {

// A chain of kKdMaxDepth inner nodes splitting x at 1 - k / 65 (each inside
// the one before): a ray along +x from x < 0 crosses every plane, so every
// node pushes its far child and the stack fills to exactly kKdMaxDepth. All
// leaves list all primitives, so every leaf answers as brute force does.
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

}  // namespace
}  // namespace rtcl::test
