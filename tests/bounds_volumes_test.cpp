// Every bounding volume (src/rtcl/bounds/: obb, kdop, sphere_bounds) contains
// every point it was built from, and every triangle of a mesh, on random
// clouds, degenerate sets and the shared meshes; degenerate and bad input
// give the documented result or error.
//
// Containment margin: the builders evaluate projections in double from float
// inputs and round the float bounds outward, so containment holds exactly up
// to the double rounding of this test's own evaluation: a dot product of
// three float products (exact in double) with two double additions errs by
// at most 2 ulp(double) of sum |n_i p_i|; a distance sqrt(sum (p - c)^2) by
// about 3 ulp of |p - c|. The margins below are 4 times that: relative to
// the point's own magnitude, never absolute.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "rtcl/bounds/kdop.hpp"
#include "rtcl/bounds/obb.hpp"
#include "rtcl/bounds/point_input.hpp"
#include "rtcl/bounds/slab_measure.hpp"
#include "rtcl/bounds/sphere_bounds.hpp"
#include "rtcl/error.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/error_of.hpp"
#include "support/fixtures.hpp"
#include "support/point_clouds.hpp"

namespace rtcl::test {
namespace {

// How far outside the slab volume p is (<= 0 inside), and the margin allowed.
bool slab_contains(const SlabVolume& v, const glm::dvec3& p, std::string* why) {
  for (int i = 0; i < v.count; ++i) {
    glm::dvec3 n(v.normal[i][0], v.normal[i][1], v.normal[i][2]);
    double d = glm::dot(n, p);
    double margin = 8.0 * DBL_EPSILON * (std::fabs(n.x * p.x) + std::fabs(n.y * p.y) + std::fabs(n.z * p.z));
    if (d < v.d_near[i] - margin || d > v.d_far[i] + margin) {
      *why = "slab " + std::to_string(i) + ": " + std::to_string(d) + " outside [" + std::to_string(v.d_near[i]) +
             ", " + std::to_string(v.d_far[i]) + "]";
      return false;
    }
  }
  return true;
}

bool sphere_contains(const BoundingSphere& s, const glm::dvec3& p) {
  double d = glm::length(p - glm::dvec3(s.center));
  return d <= s.radius + 12.0 * DBL_EPSILON * (d + s.radius);
}

// Points, and for a mesh its triangles' edge midpoints and centroids (in the
// triangles' convex hull, computed in double).
std::vector<glm::dvec3> probe_points(const std::vector<glm::vec3>& points, const Geometry* mesh) {
  std::vector<glm::dvec3> out(points.begin(), points.end());
  if (mesh)
    for (const glm::uvec3& t : mesh->triangles) {
      glm::dvec3 a(mesh->vertices[t.x]), b(mesh->vertices[t.y]), c(mesh->vertices[t.z]);
      out.push_back(0.5 * (a + b));
      out.push_back(0.5 * (b + c));
      out.push_back((a + b + c) / 3.0);
    }
  return out;
}

void expect_all_contain(const std::vector<glm::vec3>& points, const std::string& name, const Geometry* mesh) {
  std::vector<glm::dvec3> probes = probe_points(points, mesh);
  std::vector<std::pair<std::string, SlabVolume>> slabs;
  slabs.emplace_back("obb", obb_of_points(points, name).record());
  for (int count : kdop_direction_counts())
    slabs.emplace_back("kdop" + std::to_string(count), kdop_of_points(points, count, name).record());
  std::vector<std::pair<std::string, BoundingSphere>> spheres = {
      {"ritter", ritter_sphere(points, name)},
      {"iterated", iterated_ritter_sphere(points, name)},
      {"exact", exact_sphere(points, name)}};
  for (const auto& [kind, v] : slabs) {
    std::size_t outside = 0;
    std::string why;
    for (const glm::dvec3& p : probes) outside += !slab_contains(v, p, &why);
    EXPECT_EQ(outside, 0u) << name << ", " << kind << ": " << why;
  }
  for (const auto& [kind, s] : spheres) {
    std::size_t outside = 0;
    for (const glm::dvec3& p : probes) outside += !sphere_contains(s, p);
    EXPECT_EQ(outside, 0u) << name << ", " << kind;
  }
}

TEST(BoundsVolumes, ContainRandomClouds) {
  for (std::size_t n : {2u, 5u, 100u, 5000u})
    for (const PointCloud& c : random_clouds(n, 11u * static_cast<std::uint32_t>(n)))
      expect_all_contain(c.points, c.name + " n=" + std::to_string(n), nullptr);
}

TEST(BoundsVolumes, ContainFarAndTinyClouds) {
  // Scale-awareness: a cloud 1e-4 across and one centred 1e6 from the origin.
  for (const PointCloud& c : random_clouds(500, 3)) {
    std::vector<glm::vec3> tiny, far;
    for (const glm::vec3& p : c.points) tiny.push_back(1e-4f * p), far.push_back(p + glm::vec3(1e6f, -2e6f, 5e5f));
    expect_all_contain(tiny, c.name + " (tiny)", nullptr);
    expect_all_contain(far, c.name + " (far)", nullptr);
  }
}

TEST(BoundsVolumes, ContainSharedMeshesAndTheirTriangles) {
  for (const char* file : {"cornell_box/CornellBox-Original.obj", "teapot/teapot.obj", "stanford_bunny/bunny.obj"}) {
    std::string path = scene_path(file);
    Geometry g = load_mesh(path).geometry;
    expect_all_contain(used_vertices(g), path, &g);
  }
}

TEST(BoundsVolumes, DegenerateSetsHaveTheDocumentedVolumes) {
  glm::vec3 p(0.25f, -3.0f, 7.5f);
  std::vector<std::vector<glm::vec3>> sets = {
      {p},                                              // one point
      {p, p, p, p},                                     // equal points
      {p, p + glm::vec3(1, 2, 3), p + glm::vec3(2, 4, 6), p + glm::vec3(-1, -2, -3)},  // collinear
  };
  // Outward rounding leaves each zero-width slab at most 1 ulp of |p| wide:
  // volumes below (2 ulp * L)^2 * L for the collinear OBB (two flat
  // directions) and (2 ulp * L)^3 for a point, L = the largest |p|. (A
  // k-DOP of a segment is not flat: only slabs normal to it have width 0.)
  double L = glm::length(glm::dvec3(p)) + glm::length(glm::dvec3(2, 4, 6));
  double ulp = 2.0 * FLT_EPSILON * L;
  for (std::size_t k = 0; k < sets.size(); ++k) {
    expect_all_contain(sets[k], "degenerate", nullptr);
    EXPECT_LE(obb_of_points(sets[k], "degenerate").volume(), ulp * ulp * L) << k;
    if (k < 2) EXPECT_LE(measure_slabs(kdop_of_points(sets[k], 13, "degenerate").record()).volume, ulp * ulp * ulp) << k;
  }
  // One point and equal points: radius 0 for every sphere, zero-width slabs.
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(exact_sphere(sets[k], "x").radius, 0.0f);
    EXPECT_EQ(ritter_sphere(sets[k], "x").radius, 0.0f);
    EXPECT_EQ(glm::vec3(ritter_sphere(sets[k], "x").center), p);
    Obb obb = obb_of_points(sets[k], "x");
    EXPECT_EQ(obb.half_extent(), glm::vec3(0.0f));
  }
  // Collinear: every sphere's radius is half the segment (exactly the ideal one).
  double half = 0.5 * glm::length(glm::dvec3(3, 6, 9));
  EXPECT_NEAR(exact_sphere(sets[2], "x").radius, half, 1e-6 * half);
  EXPECT_NEAR(ritter_sphere(sets[2], "x").radius, half, 1e-6 * half);
  // Coplanar: zero volume, area of both sides.
  std::vector<glm::vec3> square = {{0, 0, 2}, {1, 0, 2}, {1, 1, 2}, {0, 1, 2}, {0.5f, 0.5f, 2}};
  VolumeMeasure m = measure_slabs(kdop_of_points(square, 3, "square").record());
  EXPECT_NEAR(m.volume, 0.0, 1e-9);
  EXPECT_NEAR(m.area, 2.0, 1e-6);
  EXPECT_NEAR(obb_of_points(square, "square").area(), 2.0, 1e-6);
  expect_all_contain(square, "square", nullptr);
}

TEST(BoundsVolumes, BadInputIsAClearError) {
  EXPECT_NE(error_of([] { obb_of_points({}, "cloud.txt"); }).find("cloud.txt: no points to bound"), std::string::npos);
  EXPECT_NE(error_of([] { exact_sphere({}, "cloud.txt"); }).find("no points"), std::string::npos);
  EXPECT_NE(error_of([] { kdop_of_points({}, 7, "cloud.txt"); }).find("no points"), std::string::npos);
  float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (float bad : {nan, inf, -inf}) {
    std::vector<glm::vec3> pts = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {0, bad, 0}};
    for (auto build : std::vector<std::function<void()>>{
             [&] { obb_of_points(pts, "cloud"); }, [&] { ritter_sphere(pts, "cloud"); },
             [&] { iterated_ritter_sphere(pts, "cloud"); }, [&] { exact_sphere(pts, "cloud"); },
             [&] { kdop_of_points(pts, 4, "cloud"); }})
      EXPECT_NE(error_of(build).find("cloud: point 3 has a non-finite coordinate"), std::string::npos);
  }
  EXPECT_NE(error_of([] { kdop_directions(5); }).find("unsupported direction count 5"), std::string::npos);
}

TEST(BoundsKdop, ThreeDirectionsAreTheAabbAndMeasureLikeIt) {
  PointCloud c = clustered(300, 5);
  Kdop k = kdop_of_points(c.points, 3, c.name);
  Aabb box;
  for (const glm::vec3& p : c.points) box.grow(p);
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(k.d_near[a], box.lower[a]);
    EXPECT_EQ(k.d_far[a], box.upper[a]);
  }
  glm::dvec3 e = glm::dvec3(box.upper) - glm::dvec3(box.lower);
  VolumeMeasure m = measure_slabs(k.record());
  EXPECT_NEAR(m.volume, e.x * e.y * e.z, 1e-9 * e.x * e.y * e.z);
  EXPECT_NEAR(m.area, 2 * (e.x * e.y + e.y * e.z + e.z * e.x), 1e-9 * m.area);
  // More directions never enlarge the volume: each set contains the previous
  // one's directions or cuts the AABB.
  double aabb = m.volume;
  for (int count : {7, 9, 13}) EXPECT_LE(measure_slabs(kdop_of_points(c.points, count, c.name).record()).volume, aabb * (1 + 1e-9));
}

TEST(BoundsKdop, SpheresUseTheClosedFormExtremes) {
  Geometry g;
  g.source = "spheres";
  g.spheres = {{{1.0f, 2.0f, -3.0f}, 0.5f}, {{-2.0f, 0.25f, 1.0f}, 1.5f}};
  for (int count : kdop_direction_counts()) {
    Kdop k = kdop_of_geometry(g, count);
    SlabVolume v = k.record();
    for (int i = 0; i < count; ++i) {
      glm::dvec3 n(k.normal[i]);
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (const Sphere& s : g.spheres) {
        lo = std::fmin(lo, glm::dot(n, glm::dvec3(s.center)) - s.radius * glm::length(n));
        hi = std::fmax(hi, glm::dot(n, glm::dvec3(s.center)) + s.radius * glm::length(n));
      }
      EXPECT_NEAR(k.d_near[i], lo, 4 * FLT_EPSILON * (std::fabs(lo) + 1.5));
      EXPECT_NEAR(k.d_far[i], hi, 4 * FLT_EPSILON * (std::fabs(hi) + 1.5));
      EXPECT_LE(k.d_near[i], lo);
      EXPECT_GE(k.d_far[i], hi);
    }
    // Sampled sphere surface points lie inside.
    std::string why;
    for (const Sphere& s : g.spheres)
      for (int j = 0; j < 200; ++j) {
        double th = 0.7 * j, ph = std::acos(1.0 - 2.0 * (j + 0.5) / 200.0);
        glm::dvec3 p = glm::dvec3(s.center) +
                       double(s.radius) * glm::dvec3(std::sin(ph) * std::cos(th), std::sin(ph) * std::sin(th), std::cos(ph));
        EXPECT_TRUE(slab_contains(v, p, &why)) << why;
      }
  }
}

}  // namespace
}  // namespace rtcl::test
