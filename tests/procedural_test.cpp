// The procedural scenes (src/rtcl/scene/procedural.cpp) against their closed
// forms: primitive counts, the sphereflake's touching and disjoint spheres,
// the Sierpinski tetrahedron's constant area, the mountain's crack-free
// surface and height bound, the tessellated surface's closed displaced
// torus; bad sizes refused; and the BVH agreeing with
// brute force on them (the tetrahedra meet in single shared points).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <map>
#include <string>
#include <utility>

#include "rtcl/accel.hpp"
#include "rtcl/accel/brute.hpp"
#include "rtcl/error.hpp"
#include "rtcl/scene/procedural.hpp"
#include "support/error_of.hpp"
#include "support/fixtures.hpp"
#include "support/reference.hpp"

namespace rtcl::test {
namespace {

double triangle_area(const Geometry& g, const glm::uvec3& t) {
  glm::dvec3 a(g.vertices[t.x]), b(g.vertices[t.y]), c(g.vertices[t.z]);
  return 0.5 * glm::length(glm::cross(b - a, c - a));
}

TEST(Procedural, SphereflakeCountsTouchingChildrenAndDisjointSiblings) {
  for (int levels = 0; levels <= 3; ++levels) {
    Geometry g = sphereflake(levels);
    std::size_t want = 0;
    for (int i = 0, p = 1; i <= levels; ++i, p *= 9) want += std::size_t(p);
    ASSERT_EQ(g.spheres.size(), want);
    validate(g);
  }
  Geometry g = sphereflake(1);  // the root and its nine children
  const Sphere& root = g.spheres[0];
  for (std::size_t i = 1; i < g.spheres.size(); ++i) {
    const Sphere& s = g.spheres[i];
    EXPECT_NEAR(s.radius, root.radius / 3.0f, 1e-6f);
    EXPECT_NEAR(glm::length(s.center - root.center), root.radius + s.radius, 1e-5f) << "child " << i << " touches";
    for (std::size_t j = 1; j < i; ++j)
      EXPECT_GT(glm::length(s.center - g.spheres[j].center), s.radius + g.spheres[j].radius) << i << ", " << j;
  }
}

TEST(Procedural, SierpinskiTetrahedronKeepsItsAreaAndSharesCorners) {
  const double first = std::sqrt(3.0);  // four equilateral triangles of edge 1
  for (int levels = 0; levels <= 5; ++levels) {
    Geometry g = sierpinski_tetrahedron(levels);
    ASSERT_EQ(g.triangles.size(), std::size_t(4) << (2 * levels));
    double area = 0.0;
    for (const glm::uvec3& t : g.triangles) area += triangle_area(g, t);
    EXPECT_NEAR(area, first, 1e-5 * first) << "levels " << levels;
    validate(g);
  }
  // at levels 1 each pair of the four tetrahedra meets in one vertex, bit for bit
  Geometry g = sierpinski_tetrahedron(1);
  std::map<std::tuple<float, float, float>, int> seen;
  for (const glm::vec3& v : g.vertices) ++seen[{v.x, v.y, v.z}];
  int shared = 0;
  for (const auto& [p, n] : seen) shared += n == 2;
  EXPECT_EQ(shared, 6) << "the six edge midpoints of the first tetrahedron";
}

TEST(Procedural, FractalMountainHasNoCracksAndStaysWithinItsRoughness) {
  for (int levels = 0; levels <= 5; ++levels) {
    Geometry g = fractal_mountain(levels, 3, 0.25f);
    ASSERT_EQ(g.triangles.size(), std::size_t(2) << (2 * levels));
    ASSERT_EQ(g.spheres.size(), 4u);
    validate(g);
    // every edge is shared by two triangles, except the square's border
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
    for (const glm::uvec3& t : g.triangles)
      for (auto [a, b] : {std::pair(t.x, t.y), std::pair(t.y, t.z), std::pair(t.z, t.x)})
        ++edges[{std::min(a, b), std::max(a, b)}];
    std::size_t border = 0;
    for (const auto& [e, n] : edges) {
      ASSERT_LE(n, 2);
      border += n == 1;
    }
    EXPECT_EQ(border, std::size_t(4) << levels) << "levels " << levels;
    for (const glm::vec3& v : g.vertices) EXPECT_LT(std::fabs(v.y), 0.25f);
    double area = 0.0;
    for (const glm::uvec3& t : g.triangles) area += triangle_area(g, t);
    EXPECT_GE(area, 1.0 - 1e-6) << "a displaced surface over the unit square";
  }
  EXPECT_EQ(fractal_mountain(4, 9).vertices, fractal_mountain(4, 9).vertices) << "deterministic for a seed";
  EXPECT_NE(fractal_mountain(4, 9).vertices, fractal_mountain(4, 10).vertices);
}

TEST(Procedural, TessellatedSurfaceIsAClosedDisplacedTorus) {
  for (std::size_t count : {std::size_t(18), std::size_t(1000), std::size_t(20000)}) {
    Geometry g = tessellated_surface(count);
    const std::size_t nv = std::max<std::size_t>(3, std::llround(std::sqrt(count / 8.0)));
    const std::size_t nu = std::max<std::size_t>(3, std::llround(count / (2.0 * nv)));
    ASSERT_EQ(g.triangles.size(), 2 * nu * nv) << count;
    ASSERT_EQ(g.vertices.size(), nu * nv);
    EXPECT_EQ(validate(g).zero_area_triangles, 0u);
    // closed: every edge is shared by exactly two triangles
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
    for (const glm::uvec3& t : g.triangles)
      for (auto [a, b] : {std::pair(t.x, t.y), std::pair(t.y, t.z), std::pair(t.z, t.x)})
        ++edges[{std::min(a, b), std::max(a, b)}];
    for (const auto& [e, n] : edges) ASSERT_EQ(n, 2) << count;
    // every vertex within the bumps (+-0.03) of the tube (radius 0.3) around the unit ring
    for (const glm::vec3& v : g.vertices) {
      double ring = std::hypot(double(v.x), double(v.z)) - 1.0, tube = std::hypot(ring, double(v.y));
      ASSERT_NEAR(tube, 0.3, 0.03 + 1e-6);
    }
  }
  EXPECT_EQ(tessellated_surface(1000000).triangles.size(), 999696u) << "within 0.1% of the count from 1M";
}

TEST(Procedural, SoupAndStadium) {
  Geometry soup = random_triangle_soup(1000, 4);
  ASSERT_EQ(soup.triangles.size(), 1000u);
  Aabb box = soup.bounds();
  for (int a = 0; a < 3; ++a) {
    EXPECT_GT(box.lower[a], -0.1f);
    EXPECT_LT(box.upper[a], 1.1f);
  }
  add_stadium(soup, 100.0f);
  ASSERT_EQ(soup.triangles.size(), 1012u);
  glm::vec3 e = box.extent();
  float side = 100.0f * std::max({e.x, e.y, e.z});
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(soup.bounds().extent()[a], side, 1e-5f * side);
}

TEST(Procedural, BadSizesAreErrors) {
  EXPECT_EQ(error_of([] { sphereflake(8); }), "sphereflake: levels=8: must be in [0, 7]");
  EXPECT_EQ(error_of([] { sierpinski_tetrahedron(-1); }), "tetra: levels=-1: must be in [0, 10]");
  EXPECT_EQ(error_of([] { fractal_mountain(11); }), "mount: levels=11: must be in [0, 10]");
  EXPECT_EQ(error_of([] { random_triangle_soup(0); }), "soup: count=0: must be in [1, 67108864]");
  EXPECT_EQ(error_of([] { tessellated_surface(17); }), "surface: count=17: must be in [18, 67108864]");
  Geometry g = sierpinski_tetrahedron(0);
  EXPECT_EQ(error_of([&] { add_stadium(g, 1.0f); }), "stadium: scale=1.000000: must be finite and > 1");
}

TEST(Procedural, TheBvhMatchesBruteForceOnThem) {
  for (Geometry g : {sphereflake(2), sierpinski_tetrahedron(3), fractal_mountain(4), tessellated_surface(5000)}) {
    std::vector<Ray> rays = random_rays(g, 3000, 8);
    auto brute = make_brute(test_device(), g, {});
    auto bvh = make_accel(test_device(), "bvh", g);
    for (Query q : {Query::closest, Query::any}) {
      std::vector<Hit> want = run_query(*brute, rays, q), got = run_query(*bvh, rays, q);
      std::size_t differ = 0;
      for (std::size_t i = 0; i < rays.size(); ++i)
        differ += (got[i].prim < 0) != (want[i].prim < 0) || (q == Query::closest && got[i].t != want[i].t);
      EXPECT_EQ(differ, 0u) << g.source;
    }
  }
}

}  // namespace
}  // namespace rtcl::test
