// The Embree baseline's scene (bench/support/embree_baseline.hpp) holds
// the geometry's triangles and spheres, and its answers carry rtcl's
// primitive ids: judged against the double-precision brute force, single
// rays and 8-ray packets. Built only with Embree.
#include <gtest/gtest.h>

#include <vector>

#include "bench/support/embree_baseline.hpp"
#include "support/fixtures.hpp"
#include "support/reference.hpp"

namespace rtcl::test {
namespace {

TEST(EmbreeBaseline, TracesTrianglesAndSpheresWithRtclIds) {
  Geometry g = random_soup(400, 17);
  g.spheres = {{{0.3f, 0.6f, 0.4f}, 0.12f}, {{0.8f, 0.2f, 0.7f}, 0.05f}, {{0.5f, 0.5f, 0.5f}, 0.2f}};
  bench::EmbreeScene scene(g, bench::EmbreeQuality::standard, 2);
  std::vector<Ray> rays = random_rays(g, 2000, 18);
  std::vector<Hit> references = reference_closest_all(g, rays);
  std::size_t sphere_hits = 0;
  for (const Hit& h : references) sphere_hits += h.prim >= static_cast<rtcl_i32>(g.triangles.size());
  ASSERT_GT(sphere_hits, 100u);  // the rays do reach the spheres
  for (bench::EmbreeApi api : {bench::EmbreeApi::single, bench::EmbreeApi::packet8}) {
    if (api == bench::EmbreeApi::packet8 && !bench::embree_has_packet8(2)) continue;
    std::vector<Hit> closest(rays.size()), any(rays.size());
    scene.trace(Query::closest, rays.data(), closest.data(), rays.size(), 2, api);
    std::size_t failures = 0;
    auto report = judge_all(g, rays, closest, Query::closest, references, &failures);
    EXPECT_EQ(failures, 0u) << bench::embree_api_name(api, Query::closest) << ": " << (report.empty() ? "" : report[0]);
    // Embree names no occluder, so occlusion is judged by hit or miss, against
    // the closest answers just judged (the judge accepts a hit on a ray that
    // grazes an edge within its tolerance where the reference misses).
    scene.trace(Query::any, rays.data(), any.data(), rays.size(), 2, api);
    std::size_t disagreeing = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) disagreeing += (any[i].prim >= 0) != (closest[i].prim >= 0);
    EXPECT_EQ(disagreeing, 0u) << bench::embree_api_name(api, Query::any);
  }
}

TEST(EmbreeBaseline, SpheresAloneMakeAScene) {
  Geometry g;
  g.spheres = {{{0.0f, 0.0f, 0.0f}, 1.0f}, {{3.0f, 0.0f, 0.0f}, 0.5f}};
  bench::EmbreeScene scene(g, bench::EmbreeQuality::standard, 2);
  std::vector<Ray> rays = {{-5.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 100.0f},
                           {3.0f, 0.0f, 5.0f, 0.0f, 0.0f, -1.0f, 0.0f, 100.0f},
                           {0.0f, 5.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 100.0f}};
  std::vector<Hit> hits(rays.size());
  scene.trace(Query::closest, rays.data(), hits.data(), rays.size(), 2);
  EXPECT_EQ(hits[0].prim, 0);
  EXPECT_NEAR(hits[0].t, 4.0f, 4.0f * 1e-5f);  // closed form: the near side of the unit sphere
  EXPECT_EQ(hits[1].prim, 1);
  EXPECT_NEAR(hits[1].t, 4.5f, 4.5f * 1e-5f);
  EXPECT_EQ(hits[0].u, 0.0f);  // a sphere's u, v are 0, as rtcl reports them
  EXPECT_EQ(hits[2].prim, -1);
}

}  // namespace
}  // namespace rtcl::test
