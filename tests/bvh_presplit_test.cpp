// Early split clipping (src/rtcl/accel/bvh_presplit.hpp, the bvh's
// `presplit` option): the split references cover their triangle, stay
// within its box and the budget, and the BVH built over them answers as
// brute force does, also for rays along the split planes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "rtcl/accel/bvh.hpp"
#include "rtcl/accel/bvh_presplit.hpp"
#include "rtcl/error.hpp"
#include "support/everywhere.hpp"
#include "support/fixtures.hpp"

namespace rtcl::test {
namespace {

// A small soup in [0, 1]^3 and, appended, `large` big triangles across it:
// a floor quad (two triangles, y = 0, x and z in [-1, 2]) and slanted ones.
Geometry soup_with_large_triangles(std::size_t soup, std::uint32_t seed) {
  Geometry g = random_soup(soup, seed);
  auto add = [&g](glm::vec3 a, glm::vec3 b, glm::vec3 c) {
    auto base = static_cast<std::uint32_t>(g.vertices.size());
    g.vertices.insert(g.vertices.end(), {a, b, c});
    g.triangles.push_back({base, base + 1, base + 2});
  };
  add({-1, 0, -1}, {2, 0, -1}, {2, 0, 2});
  add({-1, 0, -1}, {2, 0, 2}, {-1, 0, 2});
  add({-1, -0.5f, 0.25f}, {2, 1.5f, 0.5f}, {0.5f, 0.75f, 1.75f});
  add({0.125f, 2, -1}, {0.875f, -1, 0.5f}, {0.5f, 0.5f, 2});
  g.source = "soup with large triangles";
  return g;
}

struct References {
  std::vector<std::uint32_t> ids;
  std::vector<Aabb> bounds;
};

References triangle_references(const Geometry& g) {
  References r;
  for (std::uint32_t p = 0; p < g.triangles.size(); ++p) {
    r.ids.push_back(p);
    r.bounds.push_back(g.primitive_bounds(p));
  }
  return r;
}

TEST(Presplit, PartsCoverTheirTriangleWithinItsBox) {
  Geometry g = soup_with_large_triangles(400, 3);
  References r = triangle_references(g);
  const std::size_t n = r.ids.size();
  std::size_t refs = presplit_triangles(g, r.ids, r.bounds, n, 4.0f);
  ASSERT_EQ(refs, r.ids.size());
  ASSERT_GT(refs, n);
  ASSERT_LE(refs, kPresplitMaxGrowth * n);
  for (std::uint32_t p = 0; p < n; ++p) {
    std::vector<Aabb> parts;
    for (std::size_t i = 0; i < refs; ++i)
      if (r.ids[i] == p) parts.push_back(r.bounds[i]);
    ASSERT_FALSE(parts.empty()) << "triangle " << p << " lost";
    ASSERT_LE(parts.size(), std::size_t{1} << kPresplitMaxDepth) << "triangle " << p;
    const Aabb whole = g.primitive_bounds(p);
    for (const Aabb& part : parts) EXPECT_TRUE(whole.contains(part)) << "triangle " << p;
    if (p + 4 < n) continue;  // the soup's small triangles: not split
    EXPECT_GT(parts.size(), 1u) << "large triangle " << p << " not split";
    // Points on a barycentric lattice (vertices and edges included), each
    // in some part.
    const glm::uvec3& t = g.triangles[p];
    const glm::dvec3 a(g.vertices[t.x]), b(g.vertices[t.y]), c(g.vertices[t.z]);
    constexpr int kSteps = 64;
    for (int i = 0; i <= kSteps; ++i)
      for (int j = 0; i + j <= kSteps; ++j) {
        const double u = double(i) / kSteps, v = double(j) / kSteps;
        const glm::vec3 point(a + u * (b - a) + v * (c - a));
        EXPECT_TRUE(std::any_of(parts.begin(), parts.end(), [&](const Aabb& box) { return box.contains(point); }))
            << "large triangle " << p << " at (" << u << ", " << v << ")";
      }
  }
}

TEST(Presplit, OffOrEvenSizesKeepTheReferences) {
  Geometry g = soup_with_large_triangles(200, 5);
  References off = triangle_references(g);
  const References before = off;
  EXPECT_EQ(presplit_triangles(g, off.ids, off.bounds, off.ids.size(), 0.0f), before.ids.size());
  EXPECT_EQ(off.ids, before.ids);
  Geometry even = random_soup(300, 7);  // sizes within a factor of a few: none 16x the mean
  References r = triangle_references(even);
  EXPECT_EQ(presplit_triangles(even, r.ids, r.bounds, r.ids.size(), 16.0f), r.ids.size());
}

TEST(Presplit, ReferencesAfterTheTrianglesFollowThem) {
  Geometry g = soup_with_large_triangles(100, 9);
  References r = triangle_references(g);
  const std::size_t n = r.ids.size();
  r.ids.push_back(4242);  // stands for a sphere's reference
  r.bounds.push_back(Aabb{{5, 5, 5}, {6, 6, 6}});
  std::size_t refs = presplit_triangles(g, r.ids, r.bounds, n, 2.0f);
  ASSERT_EQ(r.ids.size(), refs + 1);
  EXPECT_EQ(r.ids.back(), 4242u);
  EXPECT_EQ(r.bounds.back().lower, glm::vec3(5));
}

TEST(Presplit, OneHugeTriangleStaysWithinTheDepthAndBudget) {
  Geometry g = random_soup(3, 11, 0.001f);
  auto base = static_cast<std::uint32_t>(g.vertices.size());
  g.vertices.insert(g.vertices.end(), {{-1000, 0, -1000}, {1000, 0, -1000}, {0, 0, 1000}});
  g.triangles.push_back({base, base + 1, base + 2});
  References r = triangle_references(g);
  std::size_t refs = presplit_triangles(g, r.ids, r.bounds, r.ids.size(), 1.0f);
  EXPECT_LE(refs, kPresplitMaxGrowth * 4);  // the budget: twice the triangles
  EXPECT_GT(refs, 4u);
}

TEST(Presplit, FlattenAcceptsRepeatedTrianglesOnlyWhenTold) {
  Geometry g = soup_with_large_triangles(300, 13);
  BvhConfig config;
  config.presplit = 1.0f;
  std::size_t stored = 0;
  BuildTree tree = build_binary_bvh(g, config, &stored);
  EXPECT_EQ(stored, g.triangles.size());
  ASSERT_GT(tree.prims.size(), stored);
  EXPECT_NO_THROW(flatten_bvh8(tree, g, {.split_references = true}));
  EXPECT_THROW(flatten_bvh8(tree, g, {.split_references = false}), Error);
}

TEST(Presplit, AnswersAsBruteForceAlsoAlongSplitPlanes) {
  Geometry g = soup_with_large_triangles(600, 17);
  g.triangles.push_back({0, 0, 1});  // zero area: skipped, and counted so
  std::vector<Ray> rays = random_rays(g, 3000, 19);
  // Down onto the floor and the slanted triangles at dyadic x and z: the
  // midpoint planes of the floor's parts (x, z = 0.5, -0.25, 1.25, ...).
  for (int i = -8; i <= 16; ++i)
    for (int k = -8; k <= 16; ++k) {
      const float x = i / 8.0f, z = k / 8.0f;
      rays.push_back(make_ray({x, 3, z}, {0, -1, 0}));
      rays.push_back(make_ray({x, 3, z}, {-0.0f, -1, 0.0f}));
      rays.push_back(make_ray({x, -0.5f, z}, {0.25f, 1, 0}));
    }
  // In the plane x = 0.5 and z = 0.5, along the floor's surface and across it.
  for (int k = -16; k <= 32; ++k) {
    const float s = k / 16.0f;
    rays.push_back(make_ray({0.5f, 1, s}, {0, -1, 0.001f}));
    rays.push_back(make_ray({s, 1, 0.5f}, {0.001f, -1, 0}));
    rays.push_back(make_ray({-2, 0, s}, {1, 0, 0}));
  }
  const Device& device = test_device();
  auto brute = make_accel(device, "brute", g);
  for (const char* name : {"bvh:presplit=1", "bvh:presplit=16", "bvh-packet:presplit=1", "bvh-ploc:presplit=1"}) {
    SCOPED_TRACE(name);
    auto accel = make_accel(device, name, g);
    EXPECT_EQ(accel->stats().zero_area_skipped, 1u);
    EXPECT_EQ(accel->stats().primitive_count, g.triangles.size() - 1);
    for (Query query : {Query::closest, Query::any})
      for (Coherence coherence : {Coherence::incoherent, Coherence::coherent}) {
        std::vector<Hit> expected = run_query(*brute, rays, query);
        std::vector<Hit> hits = run_query(*accel, rays, query, coherence);
        std::size_t wrong = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
          bool same = (hits[i].prim < 0) == (expected[i].prim < 0) &&
                      (query == Query::any || hits[i].prim < 0 || hits[i].t == expected[i].t);
          if (!same && wrong++ < 3)
            ADD_FAILURE() << "ray " << i << (query == Query::any ? " any" : " closest") << ": t " << hits[i].t
                          << " prim " << hits[i].prim << ", brute force t " << expected[i].t << " prim "
                          << expected[i].prim;
        }
        EXPECT_EQ(wrong, 0u);
      }
  }
}

}  // namespace
}  // namespace rtcl::test
