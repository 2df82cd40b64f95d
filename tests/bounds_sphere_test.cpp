// Bounding spheres (src/rtcl/bounds/sphere_bounds.cpp): the exact sphere of a
// regular simplex is its closed-form circumsphere; on small sets the exact
// sphere matches an independent brute force over all 2-, 3- and 4-point
// boundary spheres; exact <= iterated <= Ritter.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "rtcl/bounds/sphere_bounds.hpp"
#include "support/point_clouds.hpp"

namespace rtcl::test {
namespace {

struct RefBall {
  glm::dvec3 c;
  double r;
};

// Brute-force minimum enclosing sphere: the smallest sphere through 2, 3 or
// 4 of the points (circumcentre by solving the plane-restricted normal
// equations with Gaussian elimination) that contains them all.
double brute_force_radius(const std::vector<glm::dvec3>& p) {
  double best = std::numeric_limits<double>::infinity();
  auto consider = [&](glm::dvec3 c) {
    double r = 0.0;
    for (const glm::dvec3& q : p) r = std::fmax(r, glm::length(q - c));
    best = std::fmin(best, r);
  };
  std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      consider(0.5 * (p[i] + p[j]));
      for (std::size_t k = j + 1; k < n; ++k) {
        // Centre c = a + s u + t v equidistant from a, b, c: 2x2 system.
        glm::dvec3 a = p[i], u = p[j] - a, v = p[k] - a;
        double uu = glm::dot(u, u), uv = glm::dot(u, v), vv = glm::dot(v, v), det = uu * vv - uv * uv;
        if (std::fabs(det) > 1e-12 * uu * vv) {
          double s = 0.5 * (uu * vv - vv * uv) / det, t = 0.5 * (vv * uu - uu * uv) / det;
          consider(a + s * u + t * v);
        }
        for (std::size_t l = k + 1; l < n; ++l) {
          glm::dvec3 w = p[l] - a;
          glm::dmat3 m = glm::transpose(glm::dmat3(u, v, w));
          double d = glm::determinant(m);
          if (std::fabs(d) > 1e-12 * glm::length(u) * glm::length(v) * glm::length(w))
            consider(a + glm::inverse(m) * (0.5 * glm::dvec3(uu, vv, glm::dot(w, w))));
        }
      }
    }
  return best;
}

TEST(BoundsSphere, RegularSimplexMatchesTheClosedForm) {
  // Regular tetrahedron of edge a: circumradius a sqrt(6) / 4, centre the
  // centroid; equilateral triangle: a / sqrt(3); segment: a / 2.
  const glm::dvec3 tet[4] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};  // edge 2 sqrt(2)
  const glm::dvec3 tri[3] = {{1, 0, 0}, {-0.5, std::sqrt(3.0) / 2, 0}, {-0.5, -std::sqrt(3.0) / 2, 0}};  // edge sqrt(3)
  for (std::uint32_t seed = 1; seed <= 8; ++seed) {
    glm::dmat3 r = random_rotation(seed);
    double scale = std::pow(10.0, static_cast<double>(seed) - 4.0);
    glm::dvec3 shift(3.0 * seed, -1.0, 0.5 * seed);
    std::vector<glm::vec3> t4, t3, t2;
    for (const glm::dvec3& v : tet) t4.emplace_back(shift * scale + scale * (r * v));
    for (const glm::dvec3& v : tri) t3.emplace_back(shift * scale + scale * (r * v));
    t2 = {t4[0], t4[1]};
    double edge = 2.0 * std::sqrt(2.0) * scale;
    // The float rounding of the vertices moves the ideal sphere by ~1 ulp of
    // their magnitude: tolerance 8 ulp of it.
    double tol = 8.0 * FLT_EPSILON * (glm::length(shift) + 2.0) * scale;
    EXPECT_NEAR(exact_sphere(t4, "tetrahedron").radius, edge * std::sqrt(6.0) / 4.0, tol) << seed;
    EXPECT_NEAR(exact_sphere(t3, "triangle").radius, scale * 1.0, tol) << seed;
    EXPECT_NEAR(exact_sphere(t2, "segment").radius, edge / 2.0, tol) << seed;
    glm::dvec3 c = shift * scale;
    EXPECT_LE(glm::length(glm::dvec3(exact_sphere(t4, "tetrahedron").center) - c), tol) << seed;
  }
}

TEST(BoundsSphere, ExactMatchesBruteForceOnSmallSets) {
  std::mt19937 rng(99);
  for (int trial = 0; trial < 60; ++trial) {
    std::size_t n = 2 + trial % 9;
    std::vector<PointCloud> clouds = random_clouds(n, 1000u + trial);
    for (const PointCloud& c : clouds) {
      std::vector<glm::dvec3> p(c.points.begin(), c.points.end());
      double ref = brute_force_radius(p);
      BoundingSphere s = exact_sphere(c.points, c.name);
      EXPECT_NEAR(s.radius, ref, 1e-6 * ref) << c.name << " n=" << n;
    }
  }
}

TEST(BoundsSphere, ExactIsNeverLargerThanIteratedOrRitter) {
  // Each radius is rounded up to float separately (sphere_bounds.hpp): the
  // exact one may exceed an approximation equal to it by that rounding, one
  // float ulp, allowed as 2 ulp.
  for (std::size_t n : {3u, 50u, 3000u})
    for (const PointCloud& c : random_clouds(n, 5u + static_cast<std::uint32_t>(n))) {
      float exact = exact_sphere(c.points, c.name).radius;
      float iterated = iterated_ritter_sphere(c.points, c.name).radius;
      float ritter = ritter_sphere(c.points, c.name).radius;
      EXPECT_LE(exact, iterated * (1.0f + 2 * FLT_EPSILON)) << c.name << " n=" << n;
      EXPECT_LE(iterated, ritter * (1.0f + 2 * FLT_EPSILON)) << c.name << " n=" << n;
    }
}

TEST(BoundsSphere, ManyPointsOnOneSphereTerminate) {
  // Cospherical points (every point a boundary candidate) and duplicates:
  // the nested loops are bounded; the result is the sphere itself.
  std::vector<glm::vec3> pts;
  for (int i = 0; i < 4000; ++i) {
    double z = 1.0 - 2.0 * (i + 0.5) / 4000.0, phi = 2.399963 * i, s = std::sqrt(1 - z * z);
    pts.emplace_back(s * std::cos(phi), s * std::sin(phi), z);
    if (i % 7 == 0) pts.push_back(pts.back());
  }
  BoundingSphere s = exact_sphere(pts, "sphere");
  EXPECT_NEAR(s.radius, 1.0, 1e-5);
  EXPECT_LE(glm::length(s.center), 1e-5f);
}

}  // namespace
}  // namespace rtcl::test
