// Accel::signed_distance and Accel::occupancy on closed meshes: the sign
// against the winding number (the solid angle the surface subtends at the
// point, summed in double precision: 1 inside, 0 outside; Van Oosterom and
// Strackee 1983), for points at least 1e-4 of the scene's diagonal from the
// surface; the value equal to the closest point's distance.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/closed_meshes.hpp"
#include "support/error_of.hpp"
#include "support/fixtures.hpp"

namespace rtcl::test {
namespace {

// The winding number of the closed mesh around p.
double winding_number(const Geometry& mesh, const glm::vec3& p) {
  const glm::dvec3 q(p);
  double total = 0.0;
  for (const glm::uvec3& t : mesh.triangles) {
    const glm::dvec3 a = glm::dvec3(mesh.vertices[t.x]) - q, b = glm::dvec3(mesh.vertices[t.y]) - q,
                     c = glm::dvec3(mesh.vertices[t.z]) - q;
    const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
    const double num = glm::dot(a, glm::cross(b, c));
    const double den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(b, c) * la + glm::dot(c, a) * lb;
    total += 2.0 * std::atan2(num, den);
  }
  return total / (4.0 * M_PI);
}

// Points over the mesh's box widened by 10% on each side, and the
// unsigned distances the structure reports for them (kept only where they
// are at least 1e-4 of the diagonal).
std::vector<glm::vec3> spread_points(const Geometry& mesh, std::size_t count, std::uint32_t seed) {
  Aabb box = mesh.bounds();
  glm::vec3 pad = 0.1f * box.extent();
  std::mt19937 rng(seed);
  std::vector<glm::vec3> points(count);
  for (glm::vec3& p : points)
    for (int a = 0; a < 3; ++a)
      p[a] = std::uniform_real_distribution<float>(box.lower[a] - pad[a], box.upper[a] + pad[a])(rng);
  return points;
}

void expect_signs(const Geometry& mesh, std::size_t count, unsigned nsamples, const char* what) {
  auto accel = make_accel(test_device(), "bvh", mesh);
  std::vector<glm::vec3> points = spread_points(mesh, count, 7);
  std::vector<float> distance = accel->distance(points);
  std::vector<float> signed_distance = accel->signed_distance(points, nsamples);
  std::vector<std::uint8_t> occupied = accel->occupancy(points, nsamples);
  const float margin = 1e-4f * glm::length(mesh.bounds().extent());
  std::size_t judged = 0, inside = 0, wrong = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    ASSERT_EQ(std::abs(signed_distance[i]), distance[i]) << what << " point " << i;
    if (distance[i] < margin) continue;
    const bool in = std::abs(winding_number(mesh, points[i])) > 0.5;
    ++judged;
    inside += in;
    if ((signed_distance[i] < 0) != in || (occupied[i] != 0) != in) {
      if (++wrong <= 5)
        ADD_FAILURE() << what << ": point " << i << " (" << points[i].x << ", " << points[i].y << ", " << points[i].z
                      << ") is " << (in ? "inside" : "outside") << ", signed distance " << signed_distance[i]
                      << ", occupancy " << int(occupied[i]);
    }
  }
  EXPECT_EQ(wrong, 0u) << what;
  EXPECT_GT(inside, judged / 20) << what << ": too few points inside to judge the sign";
  EXPECT_GT(judged - inside, judged / 20) << what << ": too few points outside";
}

TEST(SignedDistance, IcosphereSigns) { expect_signs(icosphere(3), 3000, 1, "icosphere, 1 ray"); }

TEST(SignedDistance, CubeSignsWithRaysThroughEdges) {
  // Points on the cube's lattice planes, where single rays run along the
  // grid's edges and diagonals more often than random points would.
  expect_signs(cube_grid(4), 2000, 3, "cube, 3 rays");
}

TEST(SignedDistance, StaircaseSigns) { expect_signs(staircase(4, 2), 2000, 5, "staircase, 5 rays"); }

TEST(SignedDistance, ClosedScannedMeshSigns) {
  // The 100k-triangle dragon is closed and manifold (every edge has two
  // triangles).
  LoadedMesh dragon = load_mesh(scene_path("stanford_dragon_100k/dragon.obj"));
  expect_signs(dragon.geometry, 300, 3, "dragon, 3 rays");
}

TEST(SignedDistance, PointsOnALatticeOfTheCube) {
  // Every point on a lattice whose planes hold the cube's vertices and edges:
  // a ray parallel to an axis would run along faces; the vote's directions
  // are not parallel to any axis or diagonal, and each answer must still be
  // right.
  Geometry cube = cube_grid(4);
  auto accel = make_accel(test_device(), "bvh", cube);
  std::vector<glm::vec3> points;
  for (int i = -6; i <= 6; ++i)
    for (int j = -6; j <= 6; ++j)
      for (int k = -6; k <= 6; ++k)
        if (std::max({std::abs(i), std::abs(j), std::abs(k)}) != 4) points.emplace_back(i * 0.25f, j * 0.25f, k * 0.25f);
  std::vector<float> sd = accel->signed_distance(points, 1);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const glm::vec3& p = points[i];
    const bool in = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}) < 1.0f;
    ASSERT_EQ(sd[i] < 0, in) << "(" << p.x << ", " << p.y << ", " << p.z << "): " << sd[i];
  }
}

TEST(SignedDistance, BadInput) {
  auto accel = make_accel(test_device(), "bvh", icosphere(1));
  std::vector<glm::vec3> points = {{0, 0, 0}, {NAN, 0, 0}};
  std::string e = error_of([&] { accel->signed_distance(std::vector<glm::vec3>{{0, 0, 0}}, 2); });
  EXPECT_NE(e.find("signed_distance: nsamples is 2, must be odd"), std::string::npos) << e;
  e = error_of([&] { accel->occupancy(std::vector<glm::vec3>{{0, 0, 0}}, 0); });
  EXPECT_NE(e.find("occupancy: nsamples is 0, must be odd"), std::string::npos) << e;
  e = error_of([&] { accel->occupancy(points, 1); });
  EXPECT_NE(e.find("occupancy: points[1] has a NaN or infinite coordinate"), std::string::npos) << e;
  e = error_of([&] { accel->signed_distance(points, 1); });
  EXPECT_NE(e.find("points[1]"), std::string::npos) << e;
  auto grid = make_accel(test_device(), "grid", icosphere(1));
  e = error_of([&] { grid->occupancy(std::vector<glm::vec3>{{0, 0, 0}}, 1); });
  EXPECT_NE(e.find("grid"), std::string::npos) << e;
}

}  // namespace
}  // namespace rtcl::test
