// Embree's binary SAH tree as a BvhConfig::custom_builder
// (bench/support/embree_baseline.hpp): a well-formed tree over exactly the
// given ids, traced by the bvh kernels like rtcl's own tree. Built only with
// Embree.
#include <gtest/gtest.h>

#include <vector>

#include "rtcl/accel/bvh.hpp"
#include "bench/support/embree_baseline.hpp"
#include "support/fixtures.hpp"
#include "support/reference.hpp"

namespace rtcl::test {
namespace {

TEST(EmbreeTree, IsWellFormedAndTracedLikeTheSahTree) {
  Geometry g = random_soup(5000, 41);
  std::vector<Aabb> bounds;
  std::vector<std::uint32_t> ids;
  for (std::uint32_t p : stored_primitives(g)) {
    bounds.push_back(g.primitive_bounds(p));
    ids.push_back(p + 7);  // the caller's ids, not positions
  }
  BuildTree tree = bench::embree_binary_tree(bounds, ids, 2);
  EXPECT_EQ(check(tree, bounds, ids, RTCL_BLOCK_WIDTH), "");
  EXPECT_TRUE(bench::embree_binary_tree({}, {}, 2).empty());

  BvhConfig config;
  config.custom_builder = [](std::span<const Aabb> b, std::span<const std::uint32_t> i) {
    return bench::embree_binary_tree(b, i, 2);
  };
  auto accel = make_bvh(test_device(), g, config);
  std::vector<Ray> rays = random_rays(g, 1000, 42);
  for (Query q : {Query::closest, Query::any}) {
    std::size_t failures = 0;
    auto report = judge_all(g, rays, run_query(*accel, rays, q), q, &failures);
    EXPECT_EQ(failures, 0u) << (report.empty() ? "" : report[0]);
  }
}

}  // namespace
}  // namespace rtcl::test
