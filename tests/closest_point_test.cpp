// Closest-point queries (Accel::closest_points, distance; src/rtcl/query/
// closest_point.cpp, kernels/query/closest_point.cl) against the
// double-precision brute force of support/closest_point_reference: points on
// vertices, edges and faces of closed meshes, far away and inside them,
// random points around the bunny at three scales, spheres mixed in, a
// radius; batching across a small buffer limit and the staged path give the
// bytes of one launch; bad input throws before anything is written.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/error.hpp"
#include "rtcl/opencl.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/closed_meshes.hpp"
#include "support/closest_point_reference.hpp"
#include "support/error_of.hpp"
#include "support/fixtures.hpp"
#include "support/scoped_env.hpp"

namespace rtcl::test {
namespace {


// The structures that answer closest-point queries.
const std::vector<std::string> kFamily{"bvh", "bvh-ploc", "bvh-packet"};

Geometry scaled(Geometry g, float scale) {
  for (glm::vec3& v : g.vertices) v *= scale;
  for (Sphere& s : g.spheres) {
    s.center *= scale;
    s.radius *= scale;
  }
  return g;
}

const Geometry& bunny() {
  static const Geometry g = load_mesh(scene_path("stanford_bunny/bunny.obj")).geometry;
  return g;
}

// n points uniform over the geometry's box grown by 10% of its extent per side.
std::vector<glm::vec3> points_around(const Geometry& g, std::size_t n, std::uint32_t seed) {
  Aabb box = g.bounds();
  glm::vec3 lo = box.lower - 0.1f * box.extent(), hi = box.upper + 0.1f * box.extent();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<glm::vec3> points(n);
  for (glm::vec3& p : points) p = lo + glm::vec3(unit(rng), unit(rng), unit(rng)) * (hi - lo);
  return points;
}

// Runs the query on each structure and judges every answer.
void expect_matches_reference(const std::vector<std::string>& structures, const Geometry& g,
                              const std::vector<glm::vec3>& points, float max_distance = kInf) {
  std::vector<ReferencePoint> ref = reference_closest_points(g, points, max_distance);
  for (const std::string& structure : structures) {
    auto accel = make_accel(test_device(), structure, g);
    std::vector<PointHit> hits = accel->closest_points(points, max_distance);
    std::size_t failures = 0;
    std::vector<std::string> why = judge_closest_points(g, points, hits, ref, &failures, max_distance);
    EXPECT_EQ(failures, 0u) << structure << " on " << g.source << ": " << (why.empty() ? "" : why[0])
                            << (why.size() > 1 ? "; " + why[1] : "");
  }
}

// Points on every vertex, edge midpoint and face centroid of a mesh, pushed
// out along the face normal (far), and pulled towards the mesh's centre
// (inside).
std::vector<glm::vec3> mesh_points(const Geometry& g) {
  std::vector<glm::vec3> points = g.vertices;
  for (auto [i, j] : unique_edges(g)) points.push_back(0.5f * (g.vertices[i] + g.vertices[j]));
  glm::vec3 centre = g.bounds().center();
  float size = glm::length(g.bounds().extent());
  for (const glm::uvec3& t : g.triangles) {
    glm::vec3 a = g.vertices[t.x], b = g.vertices[t.y], c = g.vertices[t.z];
    glm::vec3 mid = (a + b + c) / 3.0f;
    points.push_back(mid);
    points.push_back(mid + 0.7f * size * glm::normalize(glm::cross(b - a, c - a)));
    points.push_back(centre + 0.5f * (mid - centre));
  }
  points.push_back(centre);
  points.push_back(centre + glm::vec3(40.0f * size, -25.0f * size, 3.0f * size));
  return points;
}

TEST(ClosestPoint, VerticesEdgesFacesOfClosedMeshes) {
  std::vector<Geometry> meshes{cube_grid(4), icosphere(2), staircase(4, 2), bumpy_sphere(2, 1.0f, 0.2f, 7)};
  for (const Geometry& g : meshes) expect_matches_reference(kFamily, g, mesh_points(g));
}

// A point on a vertex: distance exactly 0, the vertex itself, and of the
// triangles sharing it (an exact tie) the smallest id.
TEST(ClosestPoint, AVertexGoesToItsSmallestTriangle) {
  for (const Geometry& g : {cube_grid(4), uv_sphere(6, 12), staircase(3, 2)}) {
    auto users = vertex_triangles(g);
    for (const std::string& structure : kFamily) {
      auto accel = make_accel(test_device(), structure, g);
      std::vector<PointHit> hits = accel->closest_points(g.vertices);
      for (std::size_t i = 0; i < g.vertices.size(); ++i) {
        if (users[i].empty()) continue;
        std::uint32_t smallest = *std::min_element(users[i].begin(), users[i].end());
        EXPECT_EQ(hits[i].distance, 0.0f) << structure << " vertex " << i;
        EXPECT_EQ(hits[i].prim, static_cast<std::int32_t>(smallest)) << structure << " vertex " << i;
        EXPECT_EQ(glm::vec3(hits[i].x, hits[i].y, hits[i].z), g.vertices[i]) << structure << " vertex " << i;
      }
    }
  }
}

TEST(ClosestPoint, BunnyRandomPoints) {
  std::vector<glm::vec3> points = points_around(bunny(), 300, 11);
  expect_matches_reference(kFamily, bunny(), points);
}

TEST(ClosestPoint, BunnyAtTinyAndHugeScale) {
  for (float scale : {1e-6f, 1e6f}) {
    Geometry g = scaled(bunny(), scale);
    g.source = "bunny x " + std::to_string(scale);
    expect_matches_reference({"bvh"}, g, points_around(g, 200, 12));
  }
}

TEST(ClosestPoint, SpheresMixedWithTriangles) {
  Geometry g = random_soup(300, 5);
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int i = 0; i < 40; ++i) g.spheres.push_back({glm::vec3(unit(rng), unit(rng), unit(rng)), 0.01f + 0.05f * unit(rng)});
  g.source = "soup with spheres";
  std::vector<glm::vec3> points = points_around(g, 400, 13);
  for (const Sphere& s : g.spheres) {
    points.push_back(s.center);                                    // at the centre: any surface point
    points.push_back(s.center + glm::vec3(0.0f, s.radius, 0.0f));  // on the surface
  }
  expect_matches_reference(kFamily, g, points);
  // and at the extremes of scale
  for (float scale : {1e-6f, 1e6f}) {
    Geometry s = scaled(g, scale);
    expect_matches_reference({"bvh"}, s, points_around(s, 200, 14));
  }
}

TEST(ClosestPoint, MaxDistanceLeavesFartherPointsEmpty) {
  Geometry g = icosphere(3);
  std::vector<glm::vec3> points = points_around(g, 300, 15);
  for (float r : {0.0f, 0.05f, 0.3f}) expect_matches_reference({"bvh"}, g, points, r);
  auto accel = make_accel(test_device(), "bvh", g);
  std::vector<PointHit> all = accel->closest_points(points);
  std::vector<PointHit> near = accel->closest_points(points, 0.2f);
  std::size_t misses = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (all[i].distance <= 0.2f) {
      EXPECT_EQ(std::memcmp(&all[i], &near[i], sizeof(PointHit)), 0) << "point " << i;
    } else {
      ++misses;
      EXPECT_EQ(near[i].prim, -1);
      EXPECT_EQ(near[i].distance, kInf);
      EXPECT_TRUE(std::isnan(near[i].x) && std::isnan(near[i].y) && std::isnan(near[i].z));
      EXPECT_EQ(near[i].u, 0.0f);
      EXPECT_EQ(near[i].v, 0.0f);
      EXPECT_EQ(near[i].reserved, 0u);
    }
  }
  EXPECT_GT(misses, 10u);
  // the vertices themselves lie within a radius of 0
  std::vector<PointHit> on = accel->closest_points(g.vertices, 0.0f);
  for (const PointHit& h : on) EXPECT_EQ(h.distance, 0.0f);
}

TEST(ClosestPoint, DistanceIsTheClosestPointsDistance) {
  std::vector<glm::vec3> points = points_around(bunny(), 500, 16);
  auto accel = make_accel(test_device(), "bvh", bunny());
  std::vector<PointHit> hits = accel->closest_points(points);
  std::vector<float> d = accel->distance(points);
  ASSERT_EQ(d.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) EXPECT_EQ(d[i], hits[i].distance) << i;
  // three floats per point: the same answers
  std::vector<float> xyz;
  for (const glm::vec3& p : points) xyz.insert(xyz.end(), {p.x, p.y, p.z});
  EXPECT_EQ(accel->distance(Points(std::span<const float>(xyz))), d);
}

// Host arrays split into batches by a small buffer limit, through the
// shared-memory path and the staged (copy) path: the bytes of one launch on
// the caller's own cl::Buffers.
TEST(ClosestPoint, BatchesGiveTheBytesOfOneLaunch) {
  Geometry g = icosphere(2);
  std::vector<glm::vec3> points = points_around(g, 5000, 17);
  const std::size_t n = points.size();
  std::vector<PointHit> one(n);
  {
    const Device& device = test_device();
    auto accel = make_accel(device, "bvh", g);
    cl::Buffer in(device.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, n * 12, points.data());
    cl::Buffer out(device.context(), CL_MEM_WRITE_ONLY, n * sizeof(PointHit));
    accel->closest_points(in, out, n).wait();
    device.queue().enqueueReadBuffer(out, CL_TRUE, 0, n * sizeof(PointHit), one.data());
    EXPECT_EQ(error_of([&] { accel->closest_points(in, out, n + 1); }),
              "closest_points: points buffer holds 5000 points, 5001 requested");
  }
  ScopedEnv alloc("RTCL_MAX_ALLOC_BYTES", "32768");  // 1024 PointHits per batch; the structure fits
  Device small = Device::open();
  auto accel = make_accel(small, "bvh", g);
  for (const char* mode : {"shared", "copy"}) {
    ScopedEnv host_arrays("RTCL_HOST_ARRAYS", mode);
    std::vector<PointHit> batched = accel->closest_points(points);
    ASSERT_EQ(batched.size(), n);
    EXPECT_EQ(std::memcmp(batched.data(), one.data(), n * sizeof(PointHit)), 0) << mode;
  }
}

TEST(ClosestPoint, BadInputThrowsBeforeWriting) {
  Geometry g = icosphere(1);
  auto accel = make_accel(test_device(), "bvh", g);
  std::vector<glm::vec3> points(6, glm::vec3(0.5f));
  PointHit sentinel{1, 2, 3, 4, 5, 6, 7, 8};
  std::vector<PointHit> out(points.size(), sentinel);
  auto untouched = [&] {
    for (const PointHit& h : out)
      if (std::memcmp(&h, &sentinel, sizeof(PointHit)) != 0) return false;
    return true;
  };
  points[3].y = kNaN;
  EXPECT_EQ(error_of([&] { accel->closest_points(points, out); }),
            "closest_points: points[3] has a NaN or infinite coordinate");
  EXPECT_TRUE(untouched());
  points[3].y = 0.5f;
  points[4].z = -kInf;
  points[5].x = kInf;
  EXPECT_EQ(error_of([&] { accel->closest_points(points, out); }),
            "closest_points: points[4] has a NaN or infinite coordinate");
  EXPECT_EQ(error_of([&] { accel->distance(points); }), "distance: points[4] has a NaN or infinite coordinate");
  EXPECT_TRUE(untouched());
  points[4].z = points[5].x = 0.5f;
  for (float bad : {-1.0f, -kInf, kNaN}) {
    std::string e = error_of([&] { accel->closest_points(points, out, bad); });
    EXPECT_NE(e.find("closest_points: max_distance"), std::string::npos) << e;
    EXPECT_NE(e.find("must be >= 0"), std::string::npos) << e;
    EXPECT_TRUE(untouched());
  }
  EXPECT_EQ(error_of([&] { accel->closest_points(points, std::span<PointHit>(out).first(5)); }),
            "closest_points: out holds 5 records for 6 points");
  EXPECT_EQ(error_of([&] { accel->closest_points(points, std::span<PointHit>(static_cast<PointHit*>(nullptr), 6)); }),
            "closest_points: null out array");
  EXPECT_EQ(error_of([&] { accel->closest_points(Points(std::span<const float>(static_cast<const float*>(nullptr), 6))); }),
            "points: null array");
  EXPECT_TRUE(untouched());
  // no points: nothing to do, whatever the pointers
  EXPECT_EQ(error_of([&] { accel->closest_points(Points(std::span<const float>()), std::span<PointHit>()); }), "");
  EXPECT_TRUE(accel->closest_points(std::vector<glm::vec3>{}).empty());
  // and the buffer path
  cl::Buffer buffer(test_device().context(), CL_MEM_READ_WRITE, 1024);
  EXPECT_NE(error_of([&] { accel->closest_points(buffer, buffer, 1, -2.0f); }).find("max_distance"), std::string::npos);
  EXPECT_EQ(error_of([&] { accel->closest_points(buffer, buffer, 1000); }),
            "closest_points: points buffer holds 85 points, 1000 requested");
}

TEST(ClosestPoint, OtherStructuresAreRefused) {
  Geometry g = icosphere(1);
  std::vector<glm::vec3> points(2, glm::vec3(0.0f));
  auto grid = make_accel(test_device(), "grid", g);
  EXPECT_EQ(error_of([&] { grid->closest_points(points); }),
            "closest_points: structure grid does not support this query (supported: bvh, bvh-ploc, bvh-packet)");
  EXPECT_EQ(error_of([&] { grid->distance(points); }),
            "distance: structure grid does not support this query (supported: bvh, bvh-ploc, bvh-packet)");
  for (const std::string& name : accel_names()) {
    auto accel = make_accel(test_device(), name, g);
    bool family = name == "bvh" || name == "bvh-ploc" || name == "bvh-packet";
    std::string e = error_of([&] { accel->closest_points(points); });
    EXPECT_EQ(e.empty(), family) << name << ": " << e;
    if (!family) EXPECT_NE(e.find("does not support this query"), std::string::npos) << name << ": " << e;
  }
}

}  // namespace
}  // namespace rtcl::test
