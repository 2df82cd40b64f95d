// The OBB fit (src/rtcl/bounds/obb.cpp): the OBB of an axis-aligned box is
// that box; of a rotated box, that rotated box (the PCA start of a box's
// corners is its axes); never larger in area than the AABB.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <random>
#include <vector>

#include "rtcl/aabb.hpp"
#include "rtcl/bounds/obb.hpp"
#include "support/point_clouds.hpp"

namespace rtcl::test {
namespace {

// The box [lo, hi] as its 8 corners plus `inner` random points inside.
std::vector<glm::vec3> box_points(glm::dvec3 lo, glm::dvec3 hi, const glm::dmat3& rotation, int inner) {
  std::vector<glm::vec3> pts;
  for (int c = 0; c < 8; ++c) {
    glm::dvec3 p(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
    pts.emplace_back(rotation * p);
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < inner; ++i) {
    glm::dvec3 t(u(rng), u(rng), u(rng));
    pts.emplace_back(rotation * (lo + t * (hi - lo)));
  }
  return pts;
}

TEST(BoundsObb, AxisAlignedBoxIsThatBox) {
  struct Case {
    glm::dvec3 lo, hi;
  };
  for (const Case& c : {Case{{-1, -2, -3}, {4, 1, 0.5}}, Case{{0, 0, 0}, {1, 1, 1}}, Case{{10, 20, 30}, {10.5, 23, 30.25}},
                        Case{{-1e-3, 0, 0}, {1e-3, 2e-3, 5e-4}}}) {
    std::vector<glm::vec3> pts = box_points(c.lo, c.hi, glm::dmat3(1.0), 200);
    Obb obb = obb_of_points(pts, "box");
    double scale = glm::length(c.hi - c.lo) + glm::length(c.lo);
    for (int k = 0; k < 3; ++k) {
      // Each axis is a world axis up to sign; its slab is the box's.
      glm::vec3 a = glm::abs(obb.axis[k]);
      int w = a.x > 0.5f ? 0 : a.y > 0.5f ? 1 : 2;
      EXPECT_NEAR(a[w], 1.0f, 1e-6f) << k;
      EXPECT_NEAR(a[(w + 1) % 3] + a[(w + 2) % 3], 0.0f, 1e-6f) << k;
      double sign = obb.axis[k][w] > 0 ? 1.0 : -1.0;
      double lo = sign > 0 ? c.lo[w] : -c.hi[w], hi = sign > 0 ? c.hi[w] : -c.lo[w];
      EXPECT_NEAR(obb.d_near[k], lo, 1e-6 * scale) << k;
      EXPECT_NEAR(obb.d_far[k], hi, 1e-6 * scale) << k;
    }
    glm::dvec3 e = c.hi - c.lo;
    EXPECT_NEAR(obb.volume(), e.x * e.y * e.z, 1e-5 * e.x * e.y * e.z);
  }
}

TEST(BoundsObb, RotatedBoxIsFound) {
  for (std::uint32_t seed = 1; seed <= 5; ++seed) {
    glm::dmat3 r = random_rotation(seed);
    glm::dvec3 lo(-1, -0.5, -0.2), hi(2, 0.5, 0.3);
    std::vector<glm::vec3> pts = box_points(lo, hi, r, 500);
    Obb obb = obb_of_points(pts, "rotated box");
    glm::dvec3 e = hi - lo;
    double area = 2 * (e.x * e.y + e.y * e.z + e.z * e.x);
    EXPECT_NEAR(obb.area(), area, 1e-4 * area) << seed;
  }
}

TEST(BoundsObb, NeverLargerThanTheAabbAndAxesOrthonormal) {
  for (const PointCloud& c : random_clouds(2000, 21)) {
    for (std::uint32_t seed : {0u, 3u}) {
      std::vector<glm::vec3> pts = c.points;
      if (seed) {
        glm::dmat3 r = random_rotation(seed);
        for (glm::vec3& p : pts) p = glm::vec3(r * glm::dvec3(p));
      }
      Obb obb = obb_of_points(pts, c.name);
      Aabb box;
      for (const glm::vec3& p : pts) box.grow(p);
      EXPECT_LE(obb.area(), box.area() * (1.0 + 1e-6)) << c.name;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          EXPECT_NEAR(glm::dot(glm::dvec3(obb.axis[i]), glm::dvec3(obb.axis[j])), i == j ? 1.0 : 0.0, 8 * FLT_EPSILON);
    }
  }
}

}  // namespace
}  // namespace rtcl::test
