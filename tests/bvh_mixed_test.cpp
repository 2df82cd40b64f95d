// The mixed-volume BVH ("bvh-mixed", rtcl/accel/bvh_mixed.hpp): the spheres
// it chooses contain everything below them, the choice follows the costs,
// and its answers agree with brute force bit for bit and pass the
// double-precision reference, on rays aimed at the vertices and edges the
// spheres pass through. It also runs in every registry-wide suite
// (accel_names()).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "rtcl/accel/bvh_mixed.hpp"
#include "rtcl/error.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/fixtures.hpp"
#include "support/reference.hpp"

namespace rtcl::test {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Every triangle vertex below child reference `ref`, read back from the
// blocks (the leaves' contents).
void vertices_below(const Bvh8& bvh, rtcl_i32 ref, std::vector<glm::dvec3>& out) {
  if (ref >= 0) {
    for (rtcl_i32 c : bvh.nodes[static_cast<std::size_t>(ref)].child)
      if (c != RTCL_CHILD_EMPTY) vertices_below(bvh, c, out);
    return;
  }
  const TriangleBlock& b = bvh.blocks.triangles[static_cast<std::size_t>((~ref) >> 1)];
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane)
    if (b.prim[lane] >= 0)
      for (int v = 0; v < 3; ++v) out.emplace_back(b.v[v][0][lane], b.v[v][1][lane], b.v[v][2][lane]);
}

Geometry bunny() { return load_mesh(scene_path("stanford_bunny/bunny.obj")).geometry; }

TEST(BvhMixed, EverySphereContainsItsChildsVertices) {
  Geometry g = random_soup(3000, 7);
  Bvh8 bvh = flatten_bvh8(build_binary_bvh(g), g);
  BvhSphereFilters f = choose_sphere_filters(bvh, {0.0f, 4.0f}, g.source);
  ASSERT_FALSE(f.records.empty());
  std::size_t lanes = 0;
  for (std::size_t n = 0; n < bvh.nodes.size(); ++n) {
    if (f.sphere_of[n] < 0) continue;
    const Bvh8Spheres& s = f.records[static_cast<std::size_t>(f.sphere_of[n])];
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
      if (s.r[lane] < 0.0f) continue;
      ++lanes;
      std::vector<glm::dvec3> points;
      vertices_below(bvh, bvh.nodes[n].child[lane], points);
      ASSERT_FALSE(points.empty());
      glm::dvec3 c(s.cx[lane], s.cy[lane], s.cz[lane]);
      for (const glm::dvec3& p : points)
        ASSERT_LE(glm::length(p - c), static_cast<double>(s.r[lane])) << "node " << n << " lane " << lane;
    }
  }
  EXPECT_EQ(lanes, f.sphere_lanes);
}

TEST(BvhMixed, TheChoiceFollowsTheCosts) {
  Geometry g = bunny();
  Bvh8 bvh = flatten_bvh8(build_binary_bvh(g), g);
  BvhSphereFilters free_spheres = choose_sphere_filters(bvh, {0.0f, 4.0f}, g.source);
  BvhSphereFilters costly = choose_sphere_filters(bvh, {64.0f, 4.0f}, g.source);
  BvhSphereFilters measured = choose_sphere_filters(bvh, {}, g.source);
  EXPECT_TRUE(costly.records.empty());
  EXPECT_GT(free_spheres.records.size(), measured.records.size());
  EXPECT_EQ(free_spheres.sphere_of.size(), bvh.nodes.size());
  // Boxes alone are always a candidate: the chosen cost never exceeds theirs.
  for (const BvhSphereFilters* f : {&free_spheres, &costly, &measured}) {
    EXPECT_LE(f->chosen_cost, f->aabb_cost);
    EXPECT_GT(f->aabb_cost, 0.0);
  }
  EXPECT_DOUBLE_EQ(costly.chosen_cost, costly.aabb_cost);
}

TEST(BvhMixed, BadCostsAreAnError) {
  Geometry g = random_soup(50, 3);
  Bvh8 bvh = flatten_bvh8(build_binary_bvh(g), g);
  EXPECT_THROW(choose_sphere_filters(bvh, {-1.0f, 4.0f}, g.source), Error);
  EXPECT_THROW(choose_sphere_filters(bvh, {1.0f, std::numeric_limits<float>::quiet_NaN()}, g.source), Error);
  try {
    make_accel(test_device(), "bvh-mixed:sphere_cost=-1", g);
    FAIL() << "a negative sphere_cost was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("sphere_cost"), std::string::npos) << e.what();
  }
}

// Rays from outside aimed exactly at vertices and edge midpoints (the points
// a minimal sphere passes through), axis-parallel ones with ±0 components,
// and random ones.
std::vector<Ray> aimed_rays(const Geometry& g, std::uint32_t seed) {
  std::vector<Ray> rays = random_rays(g, 400, seed);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> pick(0, g.triangles.size() - 1);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  Aabb box = g.bounds();
  float reach = glm::length(box.extent()) * 2.0f;
  for (int i = 0; i < 600; ++i) {
    const glm::uvec3& t = g.triangles[pick(rng)];
    glm::vec3 v0 = g.vertices[t.x], v1 = g.vertices[t.y], v2 = g.vertices[t.z];
    glm::vec3 target = i % 3 == 0 ? v0 : i % 3 == 1 ? 0.5f * (v0 + v1) : v2;
    glm::vec3 d = glm::normalize(glm::vec3(normal(rng), normal(rng), normal(rng)));
    glm::vec3 o = target - reach * d;
    rays.push_back({o.x, o.y, o.z, d.x, d.y, d.z, 0.0f, kInf});
    // Axis-parallel, the other components +0 or -0.
    float zero = (i & 1) ? -0.0f : 0.0f;
    glm::vec3 dir(zero);
    dir[i % 3] = (i & 2) ? 1.0f : -1.0f;
    glm::vec3 from = target;
    from[i % 3] -= reach * dir[i % 3];
    rays.push_back({from.x, from.y, from.z, dir.x, dir.y, dir.z, 0.0f, kInf});
  }
  return rays;
}

// The registry-wide rule (tests/support/everywhere.cpp): the same hit or
// miss and, for closest hits, the same t as brute force at the same level;
// where the primitive differs (another one at that t, sharing an edge or a
// vertex) the answer must pass the double-precision reference's judge.
void expect_agrees(const Geometry& g, const std::vector<Ray>& rays, const std::string& spec) {
  auto brute = make_accel(test_device(), "brute", g);
  auto mixed = make_accel(test_device(), spec, g);
  for (Query q : {Query::closest, Query::any}) {
    std::vector<Hit> want = run_query(*brute, rays, q);
    std::vector<Hit> got = run_query(*mixed, rays, q);
    ASSERT_EQ(got.size(), rays.size());
    std::size_t differ = 0, judged = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      bool same = (got[i].prim < 0) == (want[i].prim < 0) &&
                  (q == Query::any || got[i].prim < 0 || got[i].t == want[i].t);
      if (!same && differ++ < 3)
        ADD_FAILURE() << spec << (q == Query::closest ? " closest" : " any") << " ray " << i << ": t " << got[i].t
                      << " prim " << got[i].prim << ", brute force t " << want[i].t << " prim " << want[i].prim;
      if (same && got[i].prim != want[i].prim) {
        ++judged;
        std::string verdict = judge(g, rays[i], got[i], q);
        EXPECT_TRUE(verdict.empty()) << spec << " ray " << i << ": " << verdict;
      }
    }
    EXPECT_EQ(differ, 0u) << spec;
    if (q == Query::closest) EXPECT_LT(judged, rays.size()) << spec;
  }
}

TEST(BvhMixed, AgreesWithBruteForceOnASoupWithSpheresEverywhere) {
  Geometry g = random_soup(4000, 11);
  expect_agrees(g, aimed_rays(g, 5), "bvh-mixed:sphere_cost=0");
}

TEST(BvhMixed, AgreesWithBruteForceOnTheBunny) {
  Geometry g = bunny();
  std::vector<Ray> rays = aimed_rays(g, 9);
  expect_agrees(g, rays, "bvh-mixed:sphere_cost=0");
  expect_agrees(g, rays, "bvh-mixed");
}

TEST(BvhMixed, FarFromTheOriginStaysConservative) {
  Geometry g = random_soup(2000, 13, 0.05f, 1.0f, glm::vec3(3.0e4f, -2.0e4f, 1.0e4f));
  expect_agrees(g, aimed_rays(g, 17), "bvh-mixed:sphere_cost=0");
}

TEST(BvhMixed, WithoutSpheresItIsThePlainKernel) {
  Geometry g = random_soup(500, 19);
  auto accel = make_accel(test_device(), "bvh-mixed:sphere_cost=64", g);
  EXPECT_EQ(accel->stats().device_bytes,
            accel->stats().node_count * sizeof(Bvh8Node) + accel->stats().leaf_count * sizeof(TriangleBlock));
  expect_agrees(g, aimed_rays(g, 23), "bvh-mixed:sphere_cost=64");
}

}  // namespace
}  // namespace rtcl::test
