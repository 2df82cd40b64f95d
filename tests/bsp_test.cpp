// The axis-aligned BSP (src/rtcl/accel/bsp.cpp, kernels/accel/kdtree.cl):
// midpoint splits with the axis rotating by depth, straddling primitives in
// both halves, and traversal answers identical to brute force on soups,
// the bunny, and rays in and on split planes.
#include <gtest/gtest.h>

#include <bit>
#include <random>

#include "rtcl/accel/bsp.hpp"
#include "rtcl/error.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/error_of.hpp"
#include "support/fixtures.hpp"
#include "support/kd_support.hpp"

namespace rtcl::test {
namespace {

// Walks the flat tree: every inner node splits its box at the middle on
// axis depth % 3; returns the leaf depth reached.
std::uint32_t check_midpoints(const KdTree& t, std::uint32_t n, glm::dvec3 lo, glm::dvec3 hi, std::uint32_t depth) {
  const KdNode& node = t.nodes[n];
  if ((node.flags & 3u) == RTCL_KD_LEAF) return depth;
  int axis = static_cast<int>(node.flags & 3u);
  EXPECT_EQ(axis, static_cast<int>(depth % 3));
  float split = std::bit_cast<float>(node.data);
  EXPECT_EQ(split, static_cast<float>(0.5 * (lo[axis] + hi[axis])));
  glm::dvec3 below_hi = hi, above_lo = lo;
  below_hi[axis] = above_lo[axis] = split;
  return std::max(check_midpoints(t, n + 1, lo, below_hi, depth + 1),
                  check_midpoints(t, node.flags >> 2, above_lo, hi, depth + 1));
}

TEST(BspBuild, MidpointSplitsRotateTheAxisAndRespectTheLimits) {
  Geometry g = random_soup(2000, 3);
  BspConfig config;
  config.depth = 9;
  config.leaf_size = 4;
  KdTree t = build_bsp(g, config);
  glm::dvec3 lo(t.header.lower[0], t.header.lower[1], t.header.lower[2]);
  glm::dvec3 hi(t.header.upper[0], t.header.upper[1], t.header.upper[2]);
  EXPECT_LE(check_midpoints(t, 0, lo, hi, 0), 9u);
  EXPECT_EQ(t.depth, 9u);
  EXPECT_GE(t.references_per_primitive(), 1.0);
  // Every leaf above the depth limit holds at most leaf_size primitives.
  EXPECT_EQ(bsp_depth({}, 1u << 16), 22);
}

TEST(BspBuild, ATriangleOnASplitPlaneIsInBothHalves) {
  Geometry g;
  g.source = "plane triangle";
  // Root box [0,1]^3 (padded): the first split is x = 0.5 (about).
  // One triangle in each half, one in the plane x = 0.5 (the split, or
  // within the widening of it).
  g.vertices = {{0, 0, 0}, {0.2f, 0, 0}, {0, 0.2f, 0.2f}, {1, 1, 1}, {0.8f, 1, 1}, {1, 0.8f, 0.8f},
                {0.5f, 0.2f, 0.2f}, {0.5f, 0.8f, 0.3f}, {0.5f, 0.5f, 0.9f}};
  g.triangles = {{0, 1, 2}, {3, 4, 5}, {6, 7, 8}};
  BspConfig config;
  config.depth = 1;
  config.leaf_size = 1;
  KdTree t = build_bsp(g, config);
  ASSERT_EQ(t.nodes.size(), 3u);
  EXPECT_EQ(t.refs, (std::vector<rtcl_i32>{0, 2, 1, 2}));
}

TEST(BspBuild, BadOptionsAreErrorsNamingTheOption) {
  Geometry g = random_soup(10, 1);
  auto message = [&](const BspConfig& c) { return error_of([&] { build_bsp(g, c); }); };
  BspConfig deep;
  deep.depth = kKdMaxDepth + 1;
  EXPECT_NE(message(deep).find("bsp: depth"), std::string::npos) << message(deep);
  BspConfig leaf;
  leaf.leaf_size = 0;
  EXPECT_NE(message(leaf).find("bsp: leaf"), std::string::npos);
  BspConfig tiny;
  tiny.max_alloc_bytes = 64;
  EXPECT_NE(message(tiny).find("bsp over"), std::string::npos) << message(tiny);
  EXPECT_NE(message(tiny).find("CL_DEVICE_MAX_MEM_ALLOC_SIZE"), std::string::npos);
  EXPECT_THROW(make_accel(test_device(), "bsp:depth=65", g), Error);
}

TEST(BspTrace, MatchesBruteForceOnSoupsAndSplitPlaneRays) {
  Geometry g = random_soup(600, 5);
  BspConfig config;
  config.leaf_size = 2;
  KdTree t = build_bsp(g, config);
  std::vector<Ray> rays = random_rays(g, 600, 6);
  std::vector<Ray> planes = split_plane_rays(t, 7, 1200);
  rays.insert(rays.end(), planes.begin(), planes.end());
  for (Precision level : test_precisions()) {
    auto bsp = make_bsp(test_device(), g, config, AccelConfig{level, {}});
    expect_same_as_brute(*bsp, g, rays, level);
  }
}

TEST(BspTrace, MatchesBruteForceOnTheBunny) {
  Geometry g = load_mesh(scene_path("stanford_bunny/bunny.obj")).geometry;
  validate(g);
  std::vector<Ray> rays = random_rays(g, 800, 41);
  std::vector<Ray> planes = split_plane_rays(build_bsp(g, {}), 43, 800);
  rays.insert(rays.end(), planes.begin(), planes.end());
  expect_same_as_brute(*make_bsp(test_device(), g), g, rays, Precision::robust, false);
}

// Coincident primitives never separate: the tree goes as deep as its
// widened node boxes can still tell them from a plane (a chain of exactly
// kKdMaxDepth splits is tests/kdtree_nodes_test.cpp's).
TEST(BspTrace, CoincidentPrimitivesAtTheMaximumDepth) {
  Geometry g;
  g.source = "coincident triangles";
  const float s = 1e-5f;
  auto add = [&](glm::vec3 p) {
    auto base = static_cast<std::uint32_t>(g.vertices.size());
    g.vertices.insert(g.vertices.end(), {p, p + glm::vec3(s, 0, 0), p + glm::vec3(0, s, s)});
    g.triangles.push_back({base, base + 1, base + 2});
  };
  for (int i = 0; i < 4; ++i) add({0.5f, 0.5f, 0.5f});
  add({0, 0, 0});
  add({1, 1, 1});
  BspConfig deepest;
  deepest.depth = kKdMaxDepth;
  deepest.leaf_size = 1;
  KdTree t = build_bsp(g, deepest);
  EXPECT_GE(t.depth, 40u);
  std::vector<Ray> rays = split_plane_rays(t, 44, 600);
  std::mt19937 rng(45);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int i = 0; i < 400; ++i) {  // at the coincident triangles
    glm::vec3 o(unit(rng) * 2 - 0.5f, unit(rng) * 2 - 0.5f, unit(rng) * 2 - 0.5f);
    glm::vec3 target = glm::vec3(0.5f) + s * glm::vec3(0.3f * unit(rng), 0.3f * unit(rng), 0.3f * unit(rng));
    glm::vec3 d = target - o;
    rays.push_back({o.x, o.y, o.z, d.x, d.y, d.z, 0.0f, INFINITY});
  }
  // The stack does not depend on the level; exact also breaks the ties of
  // the coincident triangles by id.
  for (Precision level : {Precision::robust, Precision::exact})
    expect_same_as_brute(*make_bsp(test_device(), g, deepest, AccelConfig{level, {}}), g, rays, level);
}

}  // namespace
}  // namespace rtcl::test
