// The crossing queries (src/rtcl/query/count_hits.cpp,
// kernels/query/count_hits.cl): Accel::count and Accel::all_hits against a
// double-precision brute force (support/crossings.hpp) on the bunny, a
// soup and spheres; the crossing rule on closed meshes (a ray through a
// shared edge or vertex crosses once, a silhouette touch or a ray in a
// face's plane 0 or 2 times, so the parity of a count to infinity says
// inside or outside); host-array batching; the per-ray cap; bad input.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/error.hpp"
#include "rtcl/opencl.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/closed_meshes.hpp"
#include "support/crossings.hpp"
#include "support/error_of.hpp"
#include "support/everywhere.hpp"
#include "support/fixtures.hpp"
#include "support/scoped_env.hpp"

namespace rtcl::test {
namespace {

using everywhere::describe;

const std::vector<std::string> kSupported = {"bvh", "bvh-ploc", "bvh-packet"};

// Sets an environment variable for one scope.
// Every vertex and every edge midpoint (rounded to float) of a mesh.
std::vector<glm::vec3> corners_and_edge_midpoints(const Geometry& mesh) {
  std::vector<glm::vec3> points(mesh.vertices.begin(), mesh.vertices.end());
  for (auto [a, b] : unique_edges(mesh)) points.push_back(0.5f * (mesh.vertices[a] + mesh.vertices[b]));
  return points;
}

// Checks one structure's count and all_hits against the brute force: equal
// for every ray the reference calls clear, and always consistent with each
// other (all_hits sorted, its sizes the counts).
void expect_matches_reference(const Accel& accel, const Geometry& g, const std::vector<Ray>& rays,
                              const std::vector<ReferenceCrossings>& refs, const std::string& what) {
  std::vector<std::uint32_t> counts = accel.count(rays);
  AllHits all = accel.all_hits(rays);
  ASSERT_EQ(all.ray_count(), rays.size());
  ASSERT_EQ(all.offsets[0], 0u);
  std::size_t checked = 0, failures = 0, total = 0;
  std::string first;
  auto fail = [&](std::size_t i, const std::string& why) {
    if (failures++ == 0) first = "ray " + std::to_string(i) + " " + describe(rays[i]) + ": " + why;
  };
  for (std::size_t i = 0; i < rays.size(); ++i) {
    std::span<const Hit> hits = all.of_ray(i);
    total += counts[i];
    if (hits.size() != counts[i]) fail(i, "all_hits lists " + std::to_string(hits.size()) + ", count says " +
                                              std::to_string(counts[i]));
    for (std::size_t k = 1; k < hits.size(); ++k)
      if (hits[k].t < hits[k - 1].t || (hits[k].t == hits[k - 1].t && hits[k].prim <= hits[k - 1].prim))
        fail(i, "hits not sorted by (t, prim) at " + std::to_string(k));
    if (refs[i].ambiguous) continue;
    ++checked;
    const std::vector<ReferenceCrossing>& expected = refs[i].hits;
    if (counts[i] != expected.size()) {
      fail(i, "count " + std::to_string(counts[i]) + ", reference " + std::to_string(expected.size()));
      continue;
    }
    std::vector<int> got_prims, want_prims;
    for (const Hit& h : hits) got_prims.push_back(h.prim);
    for (const ReferenceCrossing& c : expected) want_prims.push_back(c.prim);
    std::sort(got_prims.begin(), got_prims.end());
    std::sort(want_prims.begin(), want_prims.end());
    if (got_prims != want_prims) {
      fail(i, "primitives differ from the reference's");
      continue;
    }
    // t per primitive, within the reference's tolerance (a sphere's two
    // roots: both in order)
    std::vector<ReferenceCrossing> remaining = expected;
    for (const Hit& h : hits) {
      auto it = std::find_if(remaining.begin(), remaining.end(), [&](const ReferenceCrossing& c) {
        return c.prim == h.prim && std::abs(c.t - h.t) <= refs[i].t_tolerance;
      });
      if (it == remaining.end()) {
        fail(i, "prim " + std::to_string(h.prim) + " at t=" + std::to_string(h.t) + " not at the reference's t");
        break;
      }
      remaining.erase(it);
    }
  }
  EXPECT_EQ(failures, 0u) << what << ": " << first;
  EXPECT_GE(checked * 10, rays.size() * 9) << what << ": too many rays near a boundary case to be checked";
  EXPECT_GT(total, rays.size() / 2) << what << ": the rays should cross something";
}

// Rays of random_rays with the interval cut: tmax at a random fraction of
// the way for every third ray, tmin > 0 for every fifth.
std::vector<Ray> cut_rays(const Geometry& g, std::size_t count, std::uint32_t seed) {
  std::vector<Ray> rays = random_rays(g, count, seed);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.2f, 1.5f);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    if (i % 3 == 1) rays[i].tmax = u(rng);
    if (i % 5 == 2) rays[i].tmin = 0.5f * u(rng);
  }
  return rays;
}

TEST(CountHits, MatchesTheDoublePrecisionBruteForce) {
  Geometry bunny = load_mesh(scene_path("stanford_bunny/bunny.obj")).geometry;
  Geometry soup = random_soup(3000, 11, 0.15f);
  Geometry balls = random_soup(400, 5, 0.2f);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int s = 0; s < 40; ++s) balls.spheres.push_back({{u(rng), u(rng), u(rng)}, 0.02f + 0.1f * u(rng)});
  struct Case {
    const char* name;
    const Geometry* g;
    std::size_t rays;
  };
  for (const Case& c : {Case{"bunny", &bunny, 300}, Case{"soup", &soup, 1500}, Case{"soup+spheres", &balls, 1500}}) {
    std::vector<Ray> rays = cut_rays(*c.g, c.rays, 7);
    std::vector<ReferenceCrossings> refs = reference_crossings_all(*c.g, rays);
    for (const std::string& name : kSupported) {
      auto accel = make_accel(test_device(), name, *c.g);
      expect_matches_reference(*accel, *c.g, rays, refs, std::string(c.name) + " / " + name);
    }
  }
}

// The queries run the robust watertight test with the crossing rule at
// every level: the structure's level changes nothing.
TEST(CountHits, EveryPrecisionLevelGivesTheSameAnswers) {
  Geometry soup = random_soup(2000, 4, 0.15f);
  Geometry cube = cube_grid(4);
  std::vector<Ray> soup_rays = random_rays(soup, 2000, 9), cube_rays;
  for (const glm::vec3& p : corners_and_edge_midpoints(cube)) cube_rays.push_back(make_ray(glm::vec3(0.1f), p));
  for (const auto& [g, rays] : {std::make_pair(&soup, &soup_rays), std::make_pair(&cube, &cube_rays)}) {
    std::vector<std::uint32_t> base;
    AllHits base_all;
    for (Precision level : test_precisions()) {
      auto accel = make_accel(test_device(), "bvh", *g, {.precision = level});
      std::vector<std::uint32_t> counts = accel->count(*rays);
      AllHits all = accel->all_hits(*rays);
      if (base.empty()) {
        base = counts;
        base_all = all;
        continue;
      }
      EXPECT_EQ(counts, base) << precision_name(level);
      ASSERT_EQ(all.hits.size(), base_all.hits.size()) << precision_name(level);
      for (std::size_t k = 0; k < all.hits.size(); ++k) {
        EXPECT_EQ(all.hits[k].prim, base_all.hits[k].prim) << precision_name(level) << " hit " << k;
        EXPECT_EQ(all.hits[k].t, base_all.hits[k].t) << precision_name(level) << " hit " << k;
      }
    }
  }
}

struct NamedClosedMesh {
  const char* name;
  Geometry mesh;
  bool convex;  // (all are star-shaped from the origin)
};

std::vector<NamedClosedMesh> named_closed_meshes() {
  return {{"icosphere", icosphere(2), true},
          {"uv sphere", uv_sphere(8, 16), true},
          {"cube grid", cube_grid(4), true},
          {"bumpy sphere", bumpy_sphere(2, 1.0f, 0.25f, 7), false}};
}

// Counts of rays exactly through shared vertices and edges: once from the
// centre (every mesh is star-shaped from it), twice through the mesh from
// outside (convex ones), the same with +0 and -0 direction components.
TEST(CountHits, ARayThroughASharedEdgeOrVertexCrossesOnce) {
  for (const NamedClosedMesh& c : named_closed_meshes()) {
    ASSERT_EQ(open_edges(c.mesh), 0u) << c.name;
    std::vector<Ray> from_centre, through;
    for (const glm::vec3& p : corners_and_edge_midpoints(c.mesh)) {
      from_centre.push_back(make_ray(glm::vec3(0.0f), p));
      // the same with each zero component negated
      glm::vec3 flipped(p.x == 0.0f ? -0.0f : p.x, p.y == 0.0f ? -0.0f : p.y, p.z == 0.0f ? -0.0f : p.z);
      from_centre.push_back(make_ray(glm::vec3(-0.0f), flipped));
      through.push_back(make_ray(3.0f * p, -p));
    }
    for (const std::string& name : kSupported) {
      auto accel = make_accel(test_device(), name, c.mesh);
      std::vector<std::uint32_t> once = accel->count(from_centre);
      std::size_t wrong = 0;
      std::string first;
      for (std::size_t i = 0; i < once.size(); ++i)
        if (once[i] != 1 && wrong++ == 0) first = describe(from_centre[i]) + " counts " + std::to_string(once[i]);
      EXPECT_EQ(wrong, 0u) << c.name << " / " << name << ", from the centre: " << first;
      AllHits all = accel->all_hits(from_centre);
      EXPECT_EQ(all.hits.size(), from_centre.size()) << c.name << " / " << name;
      if (!c.convex) continue;
      std::vector<std::uint32_t> twice = accel->count(through);
      wrong = 0;
      for (std::size_t i = 0; i < twice.size(); ++i)
        if (twice[i] != 2 && wrong++ == 0) first = describe(through[i]) + " counts " + std::to_string(twice[i]);
      EXPECT_EQ(wrong, 0u) << c.name << " / " << name << ", through from outside: " << first;
    }
  }
}

// Rays that only touch a convex mesh: tangent at a vertex, along an edge's
// line, in a face's plane (axis-parallel ones on the cube, exactly in it;
// the face itself has zero projected area and is never hit): 0 or 2.
TEST(CountHits, SilhouetteTouchesAndInPlaneRaysCountZeroOrTwo) {
  for (const NamedClosedMesh& c : named_closed_meshes()) {
    if (!c.convex) continue;
    std::vector<Ray> rays;
    for (const glm::vec3& v : c.mesh.vertices) {
      glm::vec3 tangent = glm::normalize(glm::cross(v, glm::vec3(0.3f, 0.7f, -0.2f)));
      rays.push_back(make_ray(v - 2.0f * tangent, tangent));
    }
    for (const glm::uvec3& t : c.mesh.triangles) {
      glm::vec3 a = c.mesh.vertices[t.x], b = c.mesh.vertices[t.y], cc = c.mesh.vertices[t.z];
      // from 3 units away (outside: the faces of the cube grid are
      // coplanar with their neighbours)
      glm::vec3 e = glm::normalize(b - a);
      rays.push_back(make_ray(a - 3.0f * e, e));                    // along an edge
      rays.push_back(make_ray((a + b + cc) / 3.0f - 3.0f * e, e));  // in the face's plane
    }
    if (std::string(c.name) == "cube grid") {
      for (float y : {-1.0f, -0.5f, 0.0f, 0.5f, 1.0f})
        for (float z : {-1.0f, 1.0f})
          for (float zero : {0.0f, -0.0f}) {
            rays.push_back(make_ray({-3.0f, y, z}, {1.0f, zero, zero}));
            rays.push_back(make_ray({y, 3.0f, z}, {zero, -1.0f, zero}));
            rays.push_back(make_ray({z, y, -3.0f}, {zero, zero, 1.0f}));
          }
    }
    for (const std::string& name : kSupported) {
      auto accel = make_accel(test_device(), name, c.mesh);
      std::vector<std::uint32_t> counts = accel->count(rays);
      std::size_t wrong = 0;
      std::string first;
      for (std::size_t i = 0; i < counts.size(); ++i)
        if (counts[i] != 0 && counts[i] != 2 && wrong++ == 0)
          first = describe(rays[i]) + " counts " + std::to_string(counts[i]);
      EXPECT_EQ(wrong, 0u) << c.name << " / " << name << ": " << first;
    }
  }
}

// The parity of the count from a point to infinity is inside / outside,
// also for rays through the concave and convex edges and vertices of a
// staircase (integer lattice) from voxel centres, axis-parallel with +-0
// components and diagonal.
TEST(CountHits, ParityOfTheCountTellsInsideFromOutside) {
  const int steps = 3, depth = 2;
  Geometry stairs = staircase(steps, depth);
  ASSERT_EQ(open_edges(stairs), 0u);
  auto inside = [&](glm::vec3 p) {
    return p.x > 0 && p.x < steps && p.z > 0 && p.z < depth && p.y > 0 && p.y < steps - std::floor(p.x);
  };
  std::vector<glm::vec3> directions;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z)
        if (x || y || z) directions.push_back(glm::vec3(x, y, z));
  directions.push_back({-0.0f, 1.0f, -0.0f});
  directions.push_back({1.0f, -0.0f, 0.0f});
  directions.push_back({0.0f, -0.0f, -1.0f});
  directions.push_back({1.0f, 2.0f, 0.0f});
  directions.push_back({2.0f, -1.0f, 1.0f});
  std::vector<Ray> rays;
  std::vector<bool> expect_odd;
  for (float x = -0.5f; x < steps + 1; x += 1.0f)
    for (float y = -0.5f; y < steps + 1; y += 1.0f)
      for (float z = -0.5f; z < depth + 1; z += 1.0f)
        for (const glm::vec3& d : directions) {
          rays.push_back(make_ray({x, y, z}, d));
          expect_odd.push_back(inside({x, y, z}));
        }
  // and through the vertices and edge midpoints of the closed meshes from
  // points inside and outside
  std::vector<std::pair<Geometry, std::vector<Ray>>> meshes;
  for (const NamedClosedMesh& c : named_closed_meshes()) {
    std::vector<Ray> mesh_rays;
    for (const glm::vec3& p : corners_and_edge_midpoints(c.mesh)) {
      mesh_rays.push_back(make_ray({0.1f, -0.2f, 0.15f}, p - glm::vec3(0.1f, -0.2f, 0.15f)));
      mesh_rays.push_back(make_ray({2.5f, 1.5f, -2.0f}, p - glm::vec3(2.5f, 1.5f, -2.0f)));
    }
    meshes.emplace_back(c.mesh, std::move(mesh_rays));
  }
  for (const std::string& name : kSupported) {
    auto accel = make_accel(test_device(), name, stairs);
    std::vector<std::uint32_t> counts = accel->count(rays);
    std::size_t wrong = 0;
    std::string first;
    for (std::size_t i = 0; i < counts.size(); ++i)
      if ((counts[i] % 2 == 1) != expect_odd[i] && wrong++ == 0)
        first = describe(rays[i]) + " counts " + std::to_string(counts[i]);
    EXPECT_EQ(wrong, 0u) << "staircase / " << name << ": " << first;
    for (const auto& [mesh, mesh_rays] : meshes) {
      auto closed = make_accel(test_device(), name, mesh);
      std::vector<std::uint32_t> c = closed->count(mesh_rays);
      wrong = 0;
      for (std::size_t i = 0; i < c.size(); ++i)
        if ((c[i] % 2 == 1) != (i % 2 == 0) && wrong++ == 0)
          first = describe(mesh_rays[i]) + " counts " + std::to_string(c[i]);
      EXPECT_EQ(wrong, 0u) << mesh.source << " / " << name << ": " << first;
    }
  }
}

TEST(CountHits, InvalidRaysHaveNoCrossings) {
  Geometry g = icosphere(1);
  auto accel = make_accel(test_device(), "bvh", g);
  const glm::vec3 o(0.0f, 0.0f, -3.0f), d(0.0f, 0.0f, 1.0f);
  std::vector<Ray> rays = {
      make_ray({kNaN, 0, -3}, d),        make_ray({0, kInf, -3}, d),       make_ray(o, {0, 0, kNaN}),
      make_ray(o, {kInf, 0, 1}),         make_ray(o, {0.0f, -0.0f, 0.0f}), make_ray(o, d, kNaN, kInf),
      make_ray(o, d, 0.0f, kNaN),        make_ray(o, d, 5.0f, 1.0f),       make_ray(o, d, 2.5f, 2.5f),
      make_ray(o, d, 0.0f, 1.0f)};  // the last two are valid but cross nothing within their interval
  std::vector<std::uint32_t> counts = accel->count(rays);
  EXPECT_EQ(counts, std::vector<std::uint32_t>(rays.size(), 0u));
  AllHits all = accel->all_hits(rays);
  EXPECT_TRUE(all.hits.empty());
  EXPECT_EQ(all.offsets, std::vector<std::uint64_t>(rays.size() + 1, 0u));
  EXPECT_EQ(accel->count(std::vector<Ray>{make_ray(o, d)}), std::vector<std::uint32_t>{2u});
}

TEST(CountHits, TheCapKeepsTheNearestHitsOfEachRay) {
  Geometry soup = random_soup(3000, 2, 0.2f);
  std::vector<Ray> rays = random_rays(soup, 500, 4);
  auto accel = make_accel(test_device(), "bvh", soup);
  AllHits full = accel->all_hits(rays, kAllHitsUnlimited);
  std::size_t capped_rays = 0;
  for (std::uint32_t cap : {1u, 2u, 5u}) {
    AllHits capped = accel->all_hits(rays, cap);
    ASSERT_EQ(capped.ray_count(), rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) {
      std::span<const Hit> want = full.of_ray(i), got = capped.of_ray(i);
      ASSERT_EQ(got.size(), std::min<std::size_t>(want.size(), cap)) << "ray " << i << " cap " << cap;
      capped_rays += want.size() > cap;
      for (std::size_t k = 0; k < got.size(); ++k) {
        EXPECT_EQ(got[k].prim, want[k].prim) << "ray " << i << " cap " << cap << " hit " << k;
        EXPECT_EQ(got[k].t, want[k].t) << "ray " << i << " cap " << cap << " hit " << k;
      }
    }
  }
  EXPECT_GT(capped_rays, 100u) << "the caps should cut many rays";
  std::string e = error_of([&] { accel->all_hits(rays, 0); });
  EXPECT_NE(e.find("max_hits_per_ray"), std::string::npos) << e;
}

// Many rays through a device whose largest buffer holds 128 rays or 256
// hits: the same answers as one launch, on CPU-shared and copied host
// arrays, records and separate arrays.
TEST(CountHits, HostArraysInBatchesGiveTheAnswersOfOneLaunch) {
  Geometry g = icosphere(1);
  std::vector<Ray> rays;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < 5000; ++i) rays.push_back(make_ray({u(rng), u(rng), -3.0f}, {0.3f * u(rng), 0.3f * u(rng), 1.0f}));
  std::vector<float> origins, directions, tmin, tmax;
  for (const Ray& r : rays) {
    origins.insert(origins.end(), {r.ox, r.oy, r.oz});
    directions.insert(directions.end(), {r.dx, r.dy, r.dz});
    tmin.push_back(r.tmin);
    tmax.push_back(r.tmax);
  }
  auto whole = make_accel(test_device(), "bvh", g);
  std::vector<std::uint32_t> counts = whole->count(rays);
  AllHits all = whole->all_hits(rays);
  ASSERT_GT(all.hits.size(), 1000u);
  for (const char* mode : {"shared", "copy"}) {
    ScopedEnv limit("RTCL_MAX_ALLOC_BYTES", "4096");
    ScopedEnv host("RTCL_HOST_ARRAYS", mode);
    Device small = Device::open();
    ASSERT_EQ(small.info().max_alloc_bytes, 4096u);
    auto accel = make_accel(small, "bvh", g);
    for (const Rays& view : {Rays(rays), Rays(origins, directions, tmin, tmax)}) {
      EXPECT_EQ(accel->count(view), counts) << mode;
      AllHits batched = accel->all_hits(view);
      EXPECT_EQ(batched.offsets, all.offsets) << mode;
      ASSERT_EQ(batched.hits.size(), all.hits.size()) << mode;
      for (std::size_t k = 0; k < all.hits.size(); ++k) {
        ASSERT_EQ(batched.hits[k].prim, all.hits[k].prim) << mode << " hit " << k;
        ASSERT_EQ(batched.hits[k].t, all.hits[k].t) << mode << " hit " << k;
      }
    }
  }
}

TEST(CountHits, DeviceBuffersCountAsHostArraysDo) {
  Geometry soup = random_soup(500, 8, 0.2f);
  std::vector<Ray> rays = random_rays(soup, 1000, 3);
  auto accel = make_accel(test_device(), "bvh-packet", soup);
  const Device& device = test_device();
  cl::Buffer ray_buffer = device.upload(rays.data(), rays.size() * sizeof(Ray), "rays");
  cl::Buffer count_buffer = device.allocate(rays.size() * sizeof(std::uint32_t), "counts");
  std::vector<cl::Event> done{accel->count(ray_buffer, count_buffer, rays.size())};
  std::vector<std::uint32_t> counts(rays.size());
  device.queue().enqueueReadBuffer(count_buffer, CL_TRUE, 0, counts.size() * sizeof(std::uint32_t), counts.data(),
                                   &done);
  EXPECT_EQ(counts, accel->count(rays));
  std::string e = error_of([&] { accel->count(ray_buffer, count_buffer, rays.size() + 1); });
  EXPECT_NE(e.find("count: ray buffer holds 1000 rays"), std::string::npos) << e;
}

TEST(CountHits, BadArgumentsThrowBeforeWritingAnything) {
  Geometry g = icosphere(1);
  auto accel = make_accel(test_device(), "bvh", g);
  std::vector<Ray> rays(3, make_ray({0, 0, -3}, {0, 0, 1}));
  std::vector<std::uint32_t> counts(2, 7u);
  std::string e = error_of([&] { accel->count(rays, counts); });
  EXPECT_EQ(e, "count: counts holds 2 values for 3 rays");
  EXPECT_EQ(counts, std::vector<std::uint32_t>(2, 7u));
  e = error_of([&] { accel->count(rays, std::span<std::uint32_t>(static_cast<std::uint32_t*>(nullptr), 3)); });
  EXPECT_EQ(e, "count: null counts array");
  e = error_of([&] { accel->count(Rays(std::span<const Ray>(static_cast<const Ray*>(nullptr), 3))); });
  EXPECT_EQ(e, "count: null rays array");
  e = error_of([&] { accel->all_hits(Rays(std::span<const Ray>(static_cast<const Ray*>(nullptr), 3))); });
  EXPECT_EQ(e, "all_hits: null rays array");
  e = error_of([&] { accel->all_hits(rays, 0); });
  EXPECT_EQ(e, "all_hits: max_hits_per_ray is 0; it must be >= 1 (kAllHitsUnlimited: no cap)");
  // nothing to do is no error
  EXPECT_TRUE(accel->count(std::vector<Ray>{}).empty());
  EXPECT_EQ(accel->all_hits(std::vector<Ray>{}).offsets, std::vector<std::uint64_t>{0u});
}

TEST(CountHits, OtherStructuresRefuseNamingTheStructure) {
  Geometry g = icosphere(1);
  std::vector<Ray> rays(2, make_ray({0, 0, -3}, {0, 0, 1}));
  std::size_t refused = 0;
  for (const std::string& name : accel_names()) {
    if (std::find(kSupported.begin(), kSupported.end(), name) != kSupported.end()) continue;
    auto accel = make_accel(test_device(), name, g);
    std::vector<std::uint32_t> counts(2, 7u);
    const std::string tail = ": structure " + name + " does not support this query (supported: bvh, bvh-ploc, bvh-packet)";
    EXPECT_EQ(error_of([&] { accel->count(rays, counts); }), "count" + tail);
    EXPECT_EQ(counts, std::vector<std::uint32_t>(2, 7u)) << name;
    EXPECT_EQ(error_of([&] { accel->all_hits(rays); }), "all_hits" + tail);
    ++refused;
  }
  EXPECT_GE(refused, 3u);
}

}  // namespace
}  // namespace rtcl::test
