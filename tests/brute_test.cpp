#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "rtcl/accel/brute.hpp"
#include "support/fixtures.hpp"
#include "support/reference.hpp"

namespace rtcl::test {
namespace {

TEST(Brute, RandomSoupMatchesReference) {
  Geometry g = random_soup(300, 1);
  auto rays = random_rays(g, 2000, 2);
  auto accel = make_brute(test_device(), g);
  for (Query q : {Query::closest, Query::any}) {
    auto hits = run_query(*accel, rays, q);
    std::size_t failures = 0;
    auto report = judge_all(g, rays, hits, q, &failures);
    EXPECT_EQ(failures, 0u) << (report.empty() ? "" : report[0]);
  }
}

// The barycentrics of a hit in closed form, and the judge holding (u, v) to
// the reference: the hit point (1-u-v) v0 + u v1 + v v2, u = v = 0 on
// spheres and misses.
TEST(Brute, BarycentricsAreTheHitPointAndTheJudgeChecksThem) {
  Geometry g;
  g.source = "one triangle, one sphere";
  g.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  g.triangles = {{0, 1, 2}};
  g.spheres = {Sphere{{5, 0, 0}, 1.0f}};
  std::vector<Ray> rays = {{0.25f, 0.5f, 1, 0, 0, -1, 0, INFINITY},  // the triangle at (0.25, 0.5, 0): u 0.25, v 0.5
                           {5, 0, 3, 0, 0, -1, 0, INFINITY},         // the sphere
                           {-1, -1, 1, 0, 0, -1, 0, INFINITY}};      // nothing
  auto accel = make_brute(test_device(), g);
  for (Query q : {Query::closest, Query::any}) {
    std::vector<Hit> hits = run_query(*accel, rays, q);
    ASSERT_EQ(hits[0].prim, 0);
    EXPECT_NEAR(hits[0].t, 1.0f, 1e-6f);
    EXPECT_NEAR(hits[0].u, 0.25f, 1e-6f);
    EXPECT_NEAR(hits[0].v, 0.5f, 1e-6f);
    ASSERT_EQ(hits[1].prim, 1);
    EXPECT_EQ(hits[1].u, 0.0f);
    EXPECT_EQ(hits[1].v, 0.0f);
    EXPECT_EQ(hits[2].prim, -1);
    for (std::size_t i = 0; i < rays.size(); ++i) EXPECT_EQ(judge(g, rays[i], hits[i], q), "") << i;
    Hit swapped = hits[0];
    std::swap(swapped.u, swapped.v);
    EXPECT_NE(judge(g, rays[0], swapped, q).find("from the reference's hit point"), std::string::npos);
    Hit sphere = hits[1];
    sphere.u = 0.5f;
    EXPECT_NE(judge(g, rays[1], sphere, q).find("must be 0"), std::string::npos);
    Hit miss = hits[2];
    miss.v = 1.0f;
    EXPECT_NE(judge(g, rays[2], miss, q).find("u=v=0"), std::string::npos);
  }
}

}  // namespace
}  // namespace rtcl::test
