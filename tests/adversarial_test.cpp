// Correctness at the extremes, for every structure in tested_structures(),
// closest and any hit. Three kinds of expectation:
//  - exact ones where the geometry makes the answer exact (dyadic
//    coordinates, axis-parallel rays: the hit t is exactly known);
//  - bit-for-bit agreement with brute force: every structure runs the same
//    triangle and sphere tests, so the closest t must be identical and any-hit
//    must hit exactly when brute force does (box culling must be conservative);
//  - the double-precision reference (judge_all) everywhere else.
// What these tests establish is summarised in docs/robustness.md.
#include <gtest/gtest.h>

#include <cstdio>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "rtcl/accel.hpp"
#include "support/closed_meshes.hpp"
#include "support/error_of.hpp"
#include "support/everywhere.hpp"
#include "support/fixtures.hpp"
#include "support/reference.hpp"

namespace rtcl::test {
namespace {

using everywhere::describe;
using everywhere::query_name;
using everywhere::run_everywhere;
using everywhere::RunOptions;

// True when the triangle contains the point where the ray meets its plane
// (closed triangle, edges and vertices included, in double precision).
bool on_triangle(const Geometry& g, const Aabb& bounds, int prim, const Ray& ray, double tolerance) {
  if (prim < 0 || prim >= static_cast<int>(g.triangles.size())) return false;
  PrimHit h = reference_intersect(g, static_cast<std::uint32_t>(prim), ray, tolerance_in(bounds, ray));
  return h.plane && h.margin >= -tolerance;
}

Geometry transformed(Geometry g, double scale, glm::dvec3 offset) {
  for (auto& v : g.vertices) v = glm::vec3(glm::dvec3(v) * scale + offset);
  for (auto& s : g.spheres) {
    s.center = glm::vec3(glm::dvec3(s.center) * scale + offset);
    s.radius = static_cast<float>(s.radius * scale);
  }
  return g;
}

// ---------------------------------------------------------------------------
// Watertightness: closed meshes, rays through their vertices and edges.

struct Target {
  glm::vec3 point;
  std::vector<std::uint32_t> incident;  // triangles containing the point
};

// Every vertex and every edge midpoint of the mesh.
std::vector<Target> vertices_and_edge_midpoints(const Geometry& mesh) {
  auto by_vertex = vertex_triangles(mesh);
  std::vector<Target> targets;
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) targets.push_back({mesh.vertices[v], by_vertex[v]});
  for (auto [a, b] : unique_edges(mesh)) {
    Target t{0.5f * (mesh.vertices[a] + mesh.vertices[b]), {}};
    for (std::uint32_t tri : by_vertex[a])
      for (std::uint32_t other : by_vertex[b])
        if (tri == other) t.incident.push_back(tri);
    targets.push_back(t);
  }
  return targets;
}

bool contains(const std::vector<std::uint32_t>& set, int prim) {
  return prim >= 0 && std::find(set.begin(), set.end(), static_cast<std::uint32_t>(prim)) != set.end();
}

struct ClosedCase {
  Geometry mesh;
  glm::vec3 center;             // inside; every ray from it crosses the surface once
  std::vector<glm::vec3> more;  // other inside points
  bool convex;                  // then rays from `more` also cross once
};

std::vector<ClosedCase> closed_cases() {
  std::vector<ClosedCase> cases;
  glm::vec3 o(0.0f);
  std::vector<glm::vec3> inside = {{0.1f, -0.2f, 0.15f}, {-0.3f, 0.05f, 0.2f}, {0.0f, 0.0f, -0.4f}};
  cases.push_back({icosphere(3), o, inside, true});
  cases.push_back({uv_sphere(24, 48), o, inside, true});
  cases.push_back({cube_grid(8), o, {{0.25f, -0.5f, 0.125f}, {0.3f, 0.1f, -0.7f}}, true});
  cases.push_back({bumpy_sphere(3, 1.0f, 0.25f, 7), o, {}, false});
  // Far from the origin and large: float spacing ~2e-3 on the surface.
  glm::dvec3 away(1.0e4, -2.0e4, 3.0e4);
  Geometry moved = transformed(icosphere(3), 1000.0, away);
  moved.source = "icosphere r=1000 at (1e4, -2e4, 3e4)";
  std::vector<glm::vec3> moved_inside;
  for (glm::vec3 p : inside) moved_inside.push_back(glm::vec3(glm::dvec3(p) * 1000.0 + away));
  cases.push_back({moved, glm::vec3(away), moved_inside, true});
  return cases;
}

// A scene of zero-area triangles only has nothing to hit: every structure
// refuses it with the one message, whether validate or its own build finds
// the triangles flat (the BVH's pass over them), and also when the flat
// ones fill several build parts (over 16384 each).
TEST(Adversarial, EveryStructureRefusesASceneOfZeroAreaTrianglesOnly) {
  for (std::size_t count : {std::size_t{3}, std::size_t{40000}}) {
    Geometry g = random_soup(count, 31);
    g.source = "flat soup";
    for (glm::uvec3& t : g.triangles) t.z = t.y;
    for (const std::string& name : tested_structures()) {
      std::string e = error_of([&] { make_accel(test_device(), name, g); });
      EXPECT_NE(e.find("flat soup: empty scene"), std::string::npos) << name << ", " << count << ": " << e;
    }
  }
}

TEST(Adversarial, ClosedMeshesDoNotLeakFromInside) {
  for (const ClosedCase& c : closed_cases()) {
    ASSERT_EQ(open_edges(c.mesh), 0u) << c.mesh.source << " is not closed";
    std::vector<Target> targets = vertices_and_edge_midpoints(c.mesh);
    std::vector<Ray> rays;
    std::vector<std::size_t> target_of;
    std::vector<bool> crosses_once;
    std::vector<glm::vec3> origins = {c.center};
    origins.insert(origins.end(), c.more.begin(), c.more.end());
    for (std::size_t k = 0; k < origins.size(); ++k)
      for (std::size_t i = 0; i < targets.size(); ++i) {
        rays.push_back(make_ray(origins[k], targets[i].point - origins[k]));
        target_of.push_back(i);
        crosses_once.push_back(k == 0 || c.convex);
      }
    float extent = glm::length(c.mesh.bounds().extent());
    run_everywhere(c.mesh, rays, [&](const std::string&, Query, const std::vector<Hit>& hits) {
      std::size_t leaks = 0, wrong = 0;
      std::string first;
      for (std::size_t i = 0; i < rays.size(); ++i) {
        if (hits[i].prim < 0) {
          if (leaks++ == 0) first = "leak: ray " + describe(rays[i]);
          continue;
        }
        // The ray reaches the surface at its target (t = 1) through one of
        // the triangles that contain the target.
        const Target& target = targets[target_of[i]];
        glm::vec3 origin(rays[i].ox, rays[i].oy, rays[i].oz);
        float distance_error = std::abs(hits[i].t - 1.0f) * glm::length(target.point - origin);
        bool ok = contains(target.incident, hits[i].prim) && distance_error <= 1e-5f * extent;
        if (crosses_once[i] && !ok && wrong++ == 0 && first.empty())
          first = "ray " + describe(rays[i]) + " aimed at a vertex/edge got " + describe(hits[i]);
      }
      EXPECT_EQ(leaks, 0u) << rays.size() << " rays from inside; " << first;
      EXPECT_EQ(wrong, 0u) << first;
    }, {.judge = false, .every_ray_hits = true});
  }
}

TEST(Adversarial, ClosedMeshesDoNotLeakThroughVerticesFromOutside) {
  for (const ClosedCase& c : closed_cases()) {
    // From 4v - 3c towards c: through vertex v at t = 3, and along the line
    // from the centre through v, which (star-shaped) meets the surface only
    // at v on that side.
    std::vector<Ray> rays;
    for (const glm::vec3& v : c.mesh.vertices) {
      glm::vec3 d = c.center - v;
      rays.push_back(make_ray(v - 3.0f * d, d));
    }
    auto by_vertex = vertex_triangles(c.mesh);
    run_everywhere(c.mesh, rays, [&](const std::string&, Query query, const std::vector<Hit>& hits) {
      std::size_t misses = 0, wrong = 0;
      std::string first;
      for (std::size_t i = 0; i < rays.size(); ++i) {
        if (hits[i].prim < 0) {
          if (misses++ == 0) first = "missed: ray " + describe(rays[i]);
        } else if (query == Query::closest &&
                   (!contains(by_vertex[i], hits[i].prim) || std::abs(hits[i].t - 3.0f) > 1e-4f)) {
          if (wrong++ == 0) first = "ray " + describe(rays[i]) + " through vertex " + std::to_string(i) + " got " +
                                    describe(hits[i]);
        }
      }
      EXPECT_EQ(misses, 0u) << first;
      EXPECT_EQ(wrong, 0u) << first;
    }, {.judge = false, .every_ray_hits = true});
  }
}

TEST(Adversarial, NonConvexStaircaseDoesNotLeak) {
  Geometry stairs = staircase(4, 3);
  ASSERT_EQ(open_edges(stairs), 0u);
  // Inside points: voxel centres, and points on the interior planes through
  // the step heights (integer coordinates strictly inside the solid).
  std::vector<glm::vec3> origins = {{0.5f, 0.5f, 0.5f}, {0.5f, 3.5f, 1.5f}, {1.5f, 1.0f, 1.0f},
                                    {0.25f, 2.0f, 2.0f}, {1.0f, 1.0f, 1.0f}, {2.5f, 1.0f, 0.5f}};
  std::vector<Ray> rays;
  for (glm::vec3 o : origins) {
    for (const Target& t : vertices_and_edge_midpoints(stairs)) rays.push_back(make_ray(o, t.point - o));
    for (int axis = 0; axis < 3; ++axis)
      for (float sign : {1.0f, -1.0f})
        for (float zero : {0.0f, -0.0f}) {
          glm::vec3 d(zero);
          d[axis] = sign;
          rays.push_back(make_ray(o, d));
        }
  }
  run_everywhere(stairs, rays, [&](const std::string&, Query, const std::vector<Hit>& hits) {
    std::size_t leaks = 0;
    std::string first;
    for (std::size_t i = 0; i < rays.size(); ++i)
      if (hits[i].prim < 0 && leaks++ == 0) first = describe(rays[i]);
    EXPECT_EQ(leaks, 0u) << "first leak: " << first;
  }, {.every_ray_hits = true});
}

// ---------------------------------------------------------------------------
// Axis-parallel rays on a cube whose every coordinate is exact.

// Rays along +-axis through the 17 x 17 lattice of points spaced half a cell
// (0.125) on the cube_grid(8) faces: vertices, edges (grid lines and cell
// diagonals), and, on the lattice's border, rays lying in the plane of a
// face. Every ray has both signs of each zero direction component.
struct AxisRays {
  std::vector<Ray> rays;
  std::vector<float> expected_t;  // exact
};

AxisRays cube_axis_rays() {
  AxisRays out;
  for (int axis = 0; axis < 3; ++axis)
    for (float sign : {1.0f, -1.0f})
      for (int j = 0; j <= 16; ++j)
        for (int k = 0; k <= 16; ++k)
          for (float start : {0.0f, 0.375f, -3.0f * sign})  // two inside, one outside
            for (int zeros = 0; zeros < 4; ++zeros) {
              glm::vec3 o, d;
              o[axis] = start;
              o[(axis + 1) % 3] = -1.0f + 0.125f * j;
              o[(axis + 2) % 3] = -1.0f + 0.125f * k;
              d[axis] = sign;
              d[(axis + 1) % 3] = (zeros & 1) ? -0.0f : 0.0f;
              d[(axis + 2) % 3] = (zeros & 2) ? -0.0f : 0.0f;
              out.rays.push_back(make_ray(o, d));
              // inside: the face ahead; outside: the face nearest the origin
              float face = start == -3.0f * sign ? -sign : sign;
              out.expected_t.push_back((face - start) * sign);
            }
  return out;
}

TEST(Adversarial, AxisParallelRaysThroughCubeVerticesEdgesAndFacePlanes) {
  Geometry cube = cube_grid(8);
  const Aabb cube_bounds = cube.bounds();
  AxisRays axis = cube_axis_rays();
  run_everywhere(cube, axis.rays, [&](const std::string&, Query query, const std::vector<Hit>& hits) {
    std::size_t wrong = 0;
    std::string first;
    for (std::size_t i = 0; i < hits.size(); ++i) {
      const Ray& r = axis.rays[i];
      // Edges and vertices are inside both triangles that share them, faces
      // parallel to the ray never count: the face ahead is hit exactly.
      bool ok = hits[i].prim >= 0 && on_triangle(cube, cube_bounds, hits[i].prim, r, 0.0);
      if (query == Query::closest) ok = ok && hits[i].t == axis.expected_t[i];
      if (!ok && wrong++ == 0)
        first = "ray " + describe(r) + " expected t=" + std::to_string(axis.expected_t[i]) + ", got " +
                describe(hits[i]);
    }
    EXPECT_EQ(wrong, 0u) << "of " << hits.size() << "; first: " << first;
  }, {.judge_moved = false});
}

TEST(Adversarial, SignOfZeroDirectionComponentsDoesNotMatter) {
  // Consecutive groups of four rays in cube_axis_rays() differ only in the
  // signs of their zero components.
  Geometry stairs = staircase(4, 3);
  Geometry cube = cube_grid(8);
  AxisRays axis = cube_axis_rays();
  for (const Geometry* g : {&cube, &stairs}) {
    std::vector<Ray> rays = axis.rays;
    if (g == &stairs)  // the same lattice, shifted onto the staircase's integer planes
      for (Ray& r : rays) {
        r.ox = 4.0f * r.ox + 2.0f;
        r.oy = 4.0f * r.oy + 2.0f;
        r.oz = 2.0f * r.oz + 1.5f;
      }
    for (const std::string& name : tested_structures()) {
      auto accel = make_accel(test_device(), name, *g);
      for (Query query : {Query::closest, Query::any}) {
        std::vector<Hit> hits = run_query(*accel, rays, query);
        std::size_t differ = 0;
        std::string first;
        for (std::size_t i = 0; i < hits.size(); i += 4)
          for (std::size_t k = 1; k < 4; ++k) {
            const Hit& a = hits[i];
            const Hit& b = hits[i + k];
            bool same = (a.prim < 0) == (b.prim < 0) && (query == Query::any || a.t == b.t);
            if (!same && differ++ == 0)
              first = describe(rays[i]) + " -> " + describe(a) + " but " + describe(rays[i + k]) + " -> " +
                      describe(b);
          }
        EXPECT_EQ(differ, 0u) << name << " " << query_name(query) << " on " << g->source << ": " << first;
      }
    }
  }
}

// ---------------------------------------------------------------------------
// Grazing rays.

TEST(Adversarial, RaysInThePlaneOfAFaceHitOnlyTheEdgeAhead) {
  // In the plane y = 1 of the cube's top face, from outside, at angles within
  // the plane: the top face is parallel (never reported); the side face the
  // ray reaches is hit on its top edge.
  Geometry cube = cube_grid(8);
  const Aabb cube_bounds = cube.bounds();
  std::vector<Ray> rays;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> across(-0.9f, 0.9f), slope(-0.2f, 0.2f);
  for (int i = 0; i < 500; ++i) {
    // z where the ray reaches the face x = -1: grid vertices first
    float z = i < 17 ? -1.0f + 0.125f * i : across(rng);
    float dz = i < 100 ? 0.0f : slope(rng);
    rays.push_back(make_ray({-3.0f, 1.0f, z - 2.0f * dz}, {1.0f, 0.0f, dz}));
  }
  // Any hit may report the far face instead (the judge checks it is a hit);
  // closest hit must report the edge ahead.
  run_everywhere(cube, rays, [&](const std::string&, Query query, const std::vector<Hit>& hits) {
    if (query != Query::closest) return;
    std::size_t wrong = 0;
    std::string first;
    for (std::size_t i = 0; i < hits.size(); ++i) {
      const Ray& r = rays[i];
      bool ok = hits[i].prim >= 0 && on_triangle(cube, cube_bounds, hits[i].prim, r, 1e-6) &&
                cube.vertices[cube.triangles[hits[i].prim].x].x == -1.0f &&
                cube.vertices[cube.triangles[hits[i].prim].y].x == -1.0f &&
                std::abs(hits[i].t - 2.0f) <= 1e-6f;
      if (!ok && wrong++ == 0) first = describe(r) + " -> " + describe(hits[i]);
    }
    EXPECT_EQ(wrong, 0u) << first;
  }, {.judge_moved = false});
}

TEST(Adversarial, NearlyParallelRaysHitTheRightTriangle) {
  // A finely tessellated plane (the top face of the cube, 16 x 16 quads) and
  // rays meeting it at angles down to 1e-4 rad, from 4 units away.
  Geometry cube = cube_grid(16);
  std::vector<Ray> rays;
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> unit(-0.95f, 0.95f);
  for (float angle : {1e-1f, 1e-2f, 1e-3f, 1e-4f})
    for (int i = 0; i < 250; ++i) {
      glm::vec3 target(unit(rng), 1.0f, unit(rng));  // on the top face
      float heading = 6.2831853f * (unit(rng) + 1.0f) / 2.0f;
      glm::vec3 d(std::cos(heading) * std::cos(angle), -std::sin(angle), std::sin(heading) * std::cos(angle));
      rays.push_back(make_ray(target - 4.0f * d, d));
    }
  run_everywhere(cube, rays, {}, {.judge_moved = false});
}

// ---------------------------------------------------------------------------
// Rays lying on the planes of primitive bounds, where the faces of every
// structure's boxes lie.

TEST(Adversarial, RaysAlongPlanesThroughPrimitiveBounds) {
  Geometry soup = random_soup(400, 17, 0.1f);
  std::vector<Ray> rays;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  for (std::size_t t = 0; t < soup.triangles.size(); ++t) {
    Aabb box = soup.primitive_bounds(t);
    glm::vec3 v = soup.vertices[soup.triangles[t].x];
    for (int axis = 0; axis < 3; ++axis) {
      glm::vec3 o = v, d(0.0f);
      // axis-parallel, exactly through the vertex
      o[axis] -= 2.0f;
      d[axis] = 1.0f;
      rays.push_back(make_ray(o, d));
      // in the plane through the box's lower bound, towards the vertex
      glm::vec3 in_plane(unit(rng), unit(rng), unit(rng));
      in_plane[axis] = 0.0f;
      o = v - 2.0f * in_plane;
      o[axis] = box.lower[axis];
      rays.push_back(make_ray(o, in_plane));
      o[axis] = box.upper[axis];
      rays.push_back(make_ray(o, in_plane));
      // along an edge of the box
      o = box.lower;
      o[axis] -= 1.0f;
      rays.push_back(make_ray(o, d));
      o = box.upper;
      o[axis] += 1.0f;
      rays.push_back(make_ray(o, -d));
    }
  }
  run_everywhere(soup, rays, {});
}

// ---------------------------------------------------------------------------
// The [tmin, tmax] interval.

TEST(Adversarial, StackedQuadsAnswerExactIntervals) {
  // Quads at z = 0, 1, 2 (prims 0-1, 2-3, 4-5); the ray from z = -1 along +z
  // meets them at exactly t = 1, 2, 3.
  std::vector<float> xyz;
  std::vector<std::uint32_t> idx;
  for (int layer = 0; layer < 3; ++layer) {
    auto base = static_cast<std::uint32_t>(xyz.size() / 3);
    const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (auto& c : corners) xyz.insert(xyz.end(), {c[0], c[1], static_cast<float>(layer)});
    idx.insert(idx.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  }
  Geometry quads = Geometry::from_arrays(xyz.data(), xyz.size() / 3, idx.data(), idx.size() / 3, "stacked quads");
  const glm::vec3 o(0.3f, -0.2f, -1.0f), d(0.0f, 0.0f, 1.0f);
  struct Case {
    float tmin, tmax;
    float closest_t;  // inf: miss
  };
  const float after1 = std::nextafter(1.0f, 2.0f), before2 = std::nextafter(2.0f, 1.0f);
  const std::vector<Case> cases = {
      {0.0f, kInf, 1.0f},    {1.0f, 1.0f, 1.0f},   {2.0f, 2.0f, 2.0f},     {after1, kInf, 2.0f},
      {after1, before2, kInf}, {0.0f, before2, 1.0f}, {1.5f, 2.5f, 2.0f},   {3.0f, kInf, 3.0f},
      {std::nextafter(3.0f, 4.0f), kInf, kInf}, {0.0f, std::nextafter(1.0f, 0.0f), kInf},
      {-kInf, kInf, 1.0f},   {2.0f, 1.0f, kInf},   {kInf, kInf, kInf},     {-kInf, -kInf, kInf},
  };
  std::vector<Ray> rays;
  for (const Case& c : cases) rays.push_back(make_ray(o, d, c.tmin, c.tmax));
  run_everywhere(quads, rays, [&](const std::string&, Query query, const std::vector<Hit>& hits) {
    for (std::size_t i = 0; i < cases.size(); ++i) {
      SCOPED_TRACE(describe(rays[i]));
      if (std::isinf(cases[i].closest_t)) {
        EXPECT_EQ(hits[i].prim, -1);
        EXPECT_EQ(hits[i].t, kInf);
        continue;
      }
      ASSERT_GE(hits[i].prim, 0);
      if (query == Query::closest) {
        EXPECT_EQ(hits[i].t, cases[i].closest_t);
        EXPECT_EQ(hits[i].prim / 2, static_cast<int>(cases[i].closest_t) - 1);
      } else {
        EXPECT_GE(hits[i].t, rays[i].tmin);
        EXPECT_LE(hits[i].t, rays[i].tmax);
      }
    }
  });
}

TEST(Adversarial, IntervalEndsAtAHitIncludeItExactly) {
  // For every hit t0 of a plain query: [0, t0] and [t0, inf] and [t0, t0]
  // find t0 again; [0, before(t0)] finds nothing (t0 was the nearest).
  Geometry g = random_soup(500, 21, 0.08f);
  Geometry ball = icosphere(2, 0.3f);
  for (auto& v : ball.vertices) v += glm::vec3(0.5f);
  auto base = static_cast<std::uint32_t>(g.vertices.size());
  g.vertices.insert(g.vertices.end(), ball.vertices.begin(), ball.vertices.end());
  for (auto t : ball.triangles) g.triangles.push_back(t + glm::uvec3(base));
  std::vector<Ray> plain = random_rays(g, 3000, 22);
  for (const std::string& name : tested_structures()) {
    SCOPED_TRACE(name);
    auto accel = make_accel(test_device(), name, g);
    std::vector<Hit> first = run_query(*accel, plain, Query::closest);
    std::vector<Ray> rays;
    std::vector<float> t0;
    for (std::size_t i = 0; i < plain.size(); ++i) {
      if (first[i].prim < 0) continue;
      float t = first[i].t;
      for (auto [tmin, tmax] : {std::pair{0.0f, t}, {t, kInf}, {t, t}, {0.0f, std::nextafter(t, 0.0f)}}) {
        Ray r = plain[i];
        r.tmin = tmin;
        r.tmax = tmax;
        rays.push_back(r);
        t0.push_back(t);
      }
    }
    ASSERT_GT(rays.size(), 4000u) << "too few hits to test";
    for (Query query : {Query::closest, Query::any}) {
      std::vector<Hit> hits = run_query(*accel, rays, query);
      std::size_t wrong = 0;
      std::string example;
      for (std::size_t i = 0; i < rays.size(); ++i) {
        bool below = i % 4 == 3;  // [0, before(t0)]
        bool ok = below ? hits[i].prim < 0
                        : hits[i].prim >= 0 && (query == Query::closest ? hits[i].t == t0[i]
                                                                         : hits[i].t >= rays[i].tmin &&
                                                                               hits[i].t <= rays[i].tmax);
        if (!ok && wrong++ == 0)
          example = describe(rays[i]) + " (t0=" + std::to_string(t0[i]) + ") -> " + describe(hits[i]);
      }
      EXPECT_EQ(wrong, 0u) << query_name(query) << ": " << example;
    }
  }
}

// ---------------------------------------------------------------------------
// Origins on a surface.

TEST(Adversarial, OriginsOnASurface) {
  // Origins exactly on the cube's x = 1 face (vertices, edges, interiors),
  // directions into the cube.
  Geometry cube = cube_grid(8);
  const Aabb cube_bounds = cube.bounds();
  std::vector<Ray> axis_rays, oblique, offset;
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> unit(-0.9f, 0.9f);
  for (int j = 0; j <= 16; ++j)
    for (int k = 0; k <= 16; ++k) {
      glm::vec3 o(1.0f, -1.0f + 0.125f * j, -1.0f + 0.125f * k);
      axis_rays.push_back(make_ray(o, {-1.0f, 0.0f, 0.0f}));
      glm::vec3 d = glm::vec3(0.5f * unit(rng) - 0.3f, unit(rng), unit(rng)) - o;  // into the cube
      oblique.push_back(make_ray(o, d));
      offset.push_back(make_ray(o, d, 1e-4f));
    }
  // Along the face normal the own face is met at exactly t = 0 (tmin = 0
  // includes it): a ray leaving a surface must start past it (tmin > 0 or an
  // offset origin).
  run_everywhere(cube, axis_rays, [&](const std::string&, Query query, const std::vector<Hit>& hits) {
    for (std::size_t i = 0; i < hits.size(); ++i) {
      ASSERT_GE(hits[i].prim, 0) << describe(axis_rays[i]);
      EXPECT_TRUE(on_triangle(cube, cube_bounds, hits[i].prim, axis_rays[i], 0.0)) << describe(axis_rays[i]);
      if (query == Query::closest) EXPECT_EQ(hits[i].t, 0.0f) << describe(axis_rays[i]);
    }
  });
  // Obliquely, t of the own face is 0 up to rounding, on either side: it may
  // or may not be reported (then at |t| within the reference tolerance).
  run_everywhere(cube, oblique, [&](const std::string&, Query, const std::vector<Hit>& hits) {
    for (std::size_t i = 0; i < hits.size(); ++i) ASSERT_GE(hits[i].prim, 0) << describe(oblique[i]);
  });
  // With tmin = 1e-4 the own face is never reported; the ray crosses the
  // cube and leaves through another face.
  run_everywhere(cube, offset, [&](const std::string&, Query query, const std::vector<Hit>& hits) {
    for (std::size_t i = 0; i < hits.size(); ++i) {
      ASSERT_GE(hits[i].prim, 0) << describe(offset[i]);
      if (query == Query::closest) EXPECT_GT(hits[i].t, 0.5f) << describe(offset[i]);
    }
  });
}

// ---------------------------------------------------------------------------
// Scale: the same scene and rays, scaled and translated, answer with the same
// primitives wherever the answer is clear at both scales.

// The closest primitive when no other answer is within tolerance of being
// right: it is clearly hit, and every other primitive is clearly missed, out
// of [tmin, tmax], or clearly farther. -1: clearly nothing; -2: ambiguous.
class ClearAnswers {
 public:
  explicit ClearAnswers(const Geometry& g) : g_(g), bounds_(g.bounds()) {
    for (std::size_t p = 0; p < g.primitive_count(); ++p) {
      Aabb b = g.primitive_bounds(p);
      centers_.push_back(glm::dvec3(b.center()));
      radii_.push_back(0.5 * glm::length(glm::dvec3(b.extent())));
    }
  }

  int closest(const Ray& ray) const {
    Tolerance tol = tolerance_in(bounds_, ray);
    Hit best = reference_closest(g_, ray);
    double best_t = best.prim >= 0 ? best.t : std::numeric_limits<double>::infinity();
    glm::dvec3 o(ray.ox, ray.oy, ray.oz), d = glm::normalize(glm::dvec3(ray.dx, ray.dy, ray.dz));
    for (std::uint32_t p = 0; p < g_.primitive_count(); ++p) {
      if (static_cast<int>(p) == best.prim || (p < g_.triangles.size() && zero_area(g_, p))) continue;
      glm::dvec3 to_center = centers_[p] - o;
      double line_distance = glm::length(to_center - glm::dot(to_center, d) * d);
      if (line_distance > radii_[p] + tol.space) continue;  // the line misses its bounding sphere
      PrimHit h = reference_intersect(g_, p, ray, tol);
      if (!h.plane || h.margin < -tol.space) continue;
      if (h.t < ray.tmin - tol.t || h.t > ray.tmax + tol.t || h.t > best_t + tol.t) continue;
      return -2;
    }
    return best.prim;
  }

 private:
  const Geometry& g_;
  Aabb bounds_;
  std::vector<glm::dvec3> centers_;
  std::vector<double> radii_;
};

Geometry scale_scene() {
  Geometry g = random_soup(300, 31, 0.08f);
  g.spheres = {{{0.3f, 0.6f, 0.4f}, 0.12f}, {{0.8f, 0.2f, 0.7f}, 0.05f}, {{0.5f, 0.5f, 0.5f}, 0.2f}};
  g.source = "soup with spheres";
  return g;
}

TEST(Adversarial, ScaledAndTranslatedScenesGiveTheSameAnswers) {
  Geometry unit = scale_scene();
  std::vector<Ray> unit_rays = random_rays(unit, 2000, 32);
  struct Variant {
    double scale;
    double offset;
  };
  // Scales 1e-6 .. 1e6, translations up to 1e6. A translation of more than
  // 100 scene sizes leaves too few rays clear of the (magnitude-scaled)
  // tolerance to compare: the offsets stay within that.
  for (Variant v : {Variant{1.0, 0.0}, Variant{1e-6, 0.0}, Variant{1e-3, 0.0}, Variant{1e3, 0.0}, Variant{1e6, 0.0},
                    Variant{1e-3, 0.1}, Variant{1.0, 100.0}, Variant{1e4, 1e6}, Variant{1e6, 1e6}}) {
    Geometry g = transformed(unit, v.scale, glm::dvec3(v.offset));
    std::ostringstream name;
    name << "scene x " << v.scale << " + " << v.offset;
    g.source = name.str();
    std::vector<Ray> rays = unit_rays;
    for (Ray& r : rays) {
      glm::vec3 o = glm::vec3(glm::dvec3(r.ox, r.oy, r.oz) * v.scale + glm::dvec3(v.offset));
      glm::vec3 d = glm::vec3(glm::dvec3(r.dx, r.dy, r.dz) * v.scale);
      r = make_ray(o, d);  // t keeps its meaning: the same point at the same t
    }
    // Rays whose answer is clear at both scales must hit the same primitive.
    std::vector<int> expected(rays.size(), -2);  // -2: ambiguous at some scale
    std::size_t clear = 0;
    ClearAnswers unit_answers(unit), answers(g);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      int a = unit_answers.closest(unit_rays[i]), b = answers.closest(rays[i]);
      if (a != -2 && a == b) {
        expected[i] = a;
        ++clear;
      }
    }
    EXPECT_GT(clear, rays.size() / 2) << g.source << ": too few unambiguous rays to compare";
    run_everywhere(g, rays, [&](const std::string&, Query query, const std::vector<Hit>& hits) {
      std::size_t wrong = 0;
      std::string first;
      for (std::size_t i = 0; i < rays.size(); ++i) {
        if (expected[i] == -2) continue;
        bool ok = query == Query::closest ? hits[i].prim == expected[i] : (hits[i].prim >= 0) == (expected[i] >= 0);
        if (!ok && wrong++ == 0)
          first = describe(rays[i]) + " -> " + describe(hits[i]) + ", unscaled: prim " + std::to_string(expected[i]);
      }
      EXPECT_EQ(wrong, 0u) << g.source << ": " << first;
    });
  }
}

// ---------------------------------------------------------------------------
// Rays that cannot be traced.

TEST(Adversarial, InvalidRaysMissWithoutHanging) {
  Geometry g = scale_scene();
  const glm::vec3 o(0.5f, 0.5f, -2.0f), d(0.0f, 0.0f, 1.0f);  // a hit when valid
  std::vector<Ray> valid = {make_ray(o, d)}, invalid;
  for (int field = 0; field < 8; ++field) {
    Ray r = valid[0];
    (&r.ox)[field] = kNaN;
    invalid.push_back(r);
  }
  invalid.push_back(make_ray(o, {0.0f, 0.0f, 0.0f}));
  invalid.push_back(make_ray(o, {-0.0f, -0.0f, -0.0f}));
  invalid.push_back(make_ray(o, d, 2.0f, 1.0f));          // tmin > tmax
  invalid.push_back(make_ray(o, d, kInf, kInf));          // empty at infinity
  invalid.push_back(make_ray(o, d, -kInf, -kInf));
  invalid.push_back(make_ray(o, d, -kInf, -1.0f));        // only behind the origin
  invalid.push_back(make_ray({kInf, 0.5f, -2.0f}, d));    // infinite origin
  invalid.push_back(make_ray({0.5f, -kInf, -2.0f}, d));
  invalid.push_back(make_ray(o, {0.0f, 0.0f, kInf}));     // infinite direction
  invalid.push_back(make_ray(o, {kInf, -kInf, 1.0f}));
  // Interleaved with valid rays, which must be unaffected.
  std::vector<Ray> rays;
  for (const Ray& r : invalid) {
    rays.push_back(r);
    rays.push_back(valid[0]);
  }
  for (Precision level : test_precisions())
  for (const std::string& name : tested_structures()) {
    auto accel = make_accel(test_device(), name, g, {level});
    for (Query query : {Query::closest, Query::any}) {
      std::vector<Hit> hits = run_query(*accel, rays, query);
      for (std::size_t i = 0; i < rays.size(); i += 2) {
        SCOPED_TRACE(name + " " + std::string(precision_name(level)) + " " + query_name(query) + " " +
                     describe(rays[i]));
        EXPECT_EQ(hits[i].prim, -1);
        EXPECT_EQ(hits[i].t, kInf);
        EXPECT_EQ(hits[i].u, 0.0f);
        EXPECT_EQ(hits[i].v, 0.0f);
        EXPECT_GE(hits[i + 1].prim, 0) << "the valid ray next to it";
      }
    }
  }
}

// ---------------------------------------------------------------------------
// Spheres.

TEST(Adversarial, SphereTangentAndInsideRays) {
  Geometry g;
  g.source = "spheres";
  g.spheres = {{{0.0f, 0.0f, 0.0f}, 1.0f}, {{5.0f, 1.0f, -2.0f}, 0.25f}, {{-3.0f, 2.0f, 1.0f}, 1e-3f}};
  std::mt19937 rng(8);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  auto random_dir = [&] { return glm::normalize(glm::vec3(normal(rng), normal(rng), normal(rng))); };
  // Rays passing the centre at k radii, along random directions, from 4 radii
  // before to 4 radii after the sphere (other spheres are out of reach).
  auto passing = [&](const Sphere& s, float k) {
    glm::vec3 d = random_dir(), side = glm::normalize(glm::cross(d, random_dir()));
    return make_ray(s.center + k * s.radius * side - 4.0f * s.radius * d, d, 0.0f, 8.0f * s.radius);
  };
  std::vector<Ray> clear, tangent, inside;
  std::vector<int> inside_sphere;
  for (int s = 0; s < 3; ++s) {
    const Sphere& sphere = g.spheres[s];
    for (int i = 0; i < 100; ++i) {
      clear.push_back(passing(sphere, 1.0f - 1e-3f));
      clear.push_back(passing(sphere, 1.0f + 1e-3f));
      tangent.push_back(passing(sphere, 1.0f));
      tangent.push_back(passing(sphere, 1.0f - 1e-6f));
    }
    inside.push_back(make_ray(sphere.center, random_dir()));
    inside_sphere.push_back(s);
    // (within half a radius: far enough from the surface for the reference
    // to tell the roots apart on the smallest sphere)
    for (int i = 0; i < 200; ++i) {
      inside.push_back(make_ray(sphere.center + 0.5f * sphere.radius * std::cbrt(unit(rng)) * random_dir(),
                                random_dir()));
      inside_sphere.push_back(s);
    }
  }
  // A hit point's distance from the sphere's surface, in radii.
  auto off_surface = [&](const Ray& r, const Hit& h) {
    const Sphere& s = g.spheres[h.prim];
    glm::dvec3 p = glm::dvec3(r.ox, r.oy, r.oz) + double(h.t) * glm::dvec3(r.dx, r.dy, r.dz);
    return std::abs(glm::length(p - glm::dvec3(s.center)) / s.radius - 1.0);
  };
  run_everywhere(g, clear, {});
  // Exactly tangent (or within 1e-6 radii): hit or miss are both right, but
  // a hit is on that sphere, on its surface. (t itself is ill-conditioned
  // there: the half-chord grows as the square root of the distance.)
  // Any hit may report a sphere further along instead of the tangent one.
  run_everywhere(g, tangent, [&](const std::string&, Query query, const std::vector<Hit>& hits) {
    for (std::size_t i = 0; i < hits.size(); ++i) {
      if (hits[i].prim < 0) continue;
      if (query == Query::closest) ASSERT_EQ(hits[i].prim, static_cast<int>(i / 200)) << describe(tangent[i]);
      EXPECT_LT(off_surface(tangent[i], hits[i]), 1e-5) << describe(tangent[i]);
    }
  }, {.judge = false});
  // From inside (the centre included): the far side, at t > 0.
  run_everywhere(g, inside, [&](const std::string&, Query query, const std::vector<Hit>& hits) {
    for (std::size_t i = 0; i < hits.size(); ++i) {
      ASSERT_GE(hits[i].prim, 0) << "from inside: " << describe(inside[i]);
      if (query == Query::closest) {
        ASSERT_EQ(hits[i].prim, inside_sphere[i]) << "from inside: " << describe(inside[i]);
        EXPECT_GT(hits[i].t, 0.0f) << describe(inside[i]);
        EXPECT_LT(off_surface(inside[i], hits[i]), 1e-5) << describe(inside[i]);
      }
    }
  });
}

}  // namespace
}  // namespace rtcl::test
