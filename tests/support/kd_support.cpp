#include "support/kd_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <random>
#include <string>

#include "rtcl/accel/brute.hpp"
#include "support/everywhere.hpp"
#include "support/fixtures.hpp"
#include "support/reference.hpp"

namespace rtcl::test {

std::vector<Ray> split_plane_rays(const KdTree& tree, std::uint32_t seed, std::size_t count) {
  std::vector<float> planes[3];
  for (const KdNode& n : tree.nodes)
    if ((n.flags & 3u) != RTCL_KD_LEAF) planes[n.flags & 3u].push_back(std::bit_cast<float>(n.data));
  const KdHeader& h = tree.header;
  for (int a = 0; a < 3; ++a) {
    planes[a].push_back(h.lower[a]);
    planes[a].push_back(h.upper[a]);
  }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  auto plane = [&](int a) { return planes[a][rng() % planes[a].size()]; };
  auto inside = [&](int a) { return h.lower[a] + unit(rng) * (h.upper[a] - h.lower[a]); };
  auto zero = [&] { return (rng() & 1) ? 0.0f : -0.0f; };
  std::vector<Ray> rays;
  for (std::size_t i = 0; i < count; ++i) {
    glm::vec3 o, d;
    for (int a = 0; a < 3; ++a) {
      o[a] = inside(a);
      d[a] = normal(rng);
    }
    int a = static_cast<int>(rng() % 3);
    switch (i % 6) {
      case 0:  // in a split plane, oblique within it
        o[a] = plane(a);
        d[a] = zero();
        break;
      case 1:  // axis-parallel along two planes (a leaf edge), from outside
        d = glm::vec3(zero(), zero(), zero());
        d[a] = (rng() & 1) ? 1.0f : -1.0f;
        o[(a + 1) % 3] = plane((a + 1) % 3);
        o[(a + 2) % 3] = plane((a + 2) % 3);
        o[a] = d[a] > 0 ? h.lower[a] - 1.0f : h.upper[a] + 1.0f;
        break;
      case 2:  // starting on a plane, any direction
        o[a] = plane(a);
        break;
      case 3:  // through a point where three planes meet
        for (int b = 0; b < 3; ++b) d[b] = plane(b) - o[b];
        break;
      case 4:  // axis-parallel from inside a leaf (±0 elsewhere)
        d = glm::vec3(zero(), zero(), zero());
        d[a] = (rng() & 1) ? 1.0f : -1.0f;
        break;
      default:  // from outside the root box towards a point on a plane
        glm::vec3 target(inside(0), inside(1), inside(2));
        target[a] = plane(a);
        for (int b = 0; b < 3; ++b) o[b] = target[b] + 2.0f * (h.upper[b] - h.lower[b]) * normal(rng);
        d = target - o;
    }
    if (d == glm::vec3(0.0f)) d.x = 1.0f;
    rays.push_back(make_ray(o, d));
  }
  return rays;
}

void expect_same_as_brute(const Accel& accel, const Geometry& geometry, const std::vector<Ray>& rays,
                          Precision level, bool judge) {
  auto brute = make_brute(test_device(), geometry, AccelConfig{level, {}});
  const Aabb bounds = geometry.bounds();
  for (Query q : {Query::closest, Query::any}) {
    SCOPED_TRACE(std::string(everywhere::query_name(q)) + " at level " + std::string(precision_name(level)) +
                 " on " + geometry.source + " by " + accel.name());
    auto expected = run_query(*brute, rays, q);
    auto hits = run_query(accel, rays, q);
    std::size_t differ = 0;
    std::string first;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      bool same = (hits[i].prim < 0) == (expected[i].prim < 0);
      // At the fast level the programs may round differently: within 1e-5
      // of t, or of the scene's scale along the ray for a hit close to the
      // origin (tolerance_in, 16 float ulps).
      if (same && q == Query::closest && hits[i].prim >= 0)
        same = level == Precision::fast
                   ? std::fabs(hits[i].t - expected[i].t) <=
                         std::max(1e-5 * std::fabs(expected[i].t), tolerance_in(bounds, rays[i], 16.0).t)
                   : hits[i].t == expected[i].t;
      if (!same && differ++ == 0)
        first = "ray " + std::to_string(i) + " " + everywhere::describe(rays[i]) + ": " + accel.name() + " " +
                everywhere::describe(hits[i]) + ", brute " + everywhere::describe(expected[i]);
    }
    EXPECT_EQ(differ, 0u) << "of " << rays.size() << " rays; first: " << first;
    if (judge && level == Precision::robust) {
      std::size_t failures = 0;
      auto report = judge_all(geometry, rays, hits, q, &failures);
      EXPECT_EQ(failures, 0u) << (report.empty() ? "" : report[0]);
    }
  }
}

}  // namespace rtcl::test
