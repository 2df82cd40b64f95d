// The uniform grid (src/rtcl/accel/grid.cpp, kernels/accel/grid.cl): the
// resolution heuristic, exact and conservative cell lists, and traversal
// answers identical to brute force (same t, bit for bit, at the robust and
// exact levels) on soups, real meshes and rays aimed at cell planes, edges
// and corners, for closest and any hit, at every precision level.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "rtcl/accel/brute.hpp"
#include "rtcl/accel/grid.hpp"
#include "rtcl/bounds/overlap.hpp"
#include "rtcl/error.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/fixtures.hpp"
#include "support/reference.hpp"

namespace rtcl::test {
namespace {



const Precision kLevels[] = {Precision::fast, Precision::robust, Precision::exact};

float plane(const GridHeader& g, int a, int n) { return g.lower[a] + static_cast<float>(n) * g.cell[a]; }

// Rays that stress the DDA: along cell planes, through cell edges and grid
// corners, axis-parallel, starting on boundaries, inside the grid and
// outside it, in every direction octant, with zero components.
std::vector<Ray> cell_boundary_rays(const Grid& grid, std::uint32_t seed, std::size_t count) {
  const GridHeader& g = grid.header;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  auto plane_coord = [&](int a) {
    std::uniform_int_distribution<int> n(0, g.res[a]);
    return plane(g, a, n(rng));
  };
  auto inside = [&](int a) { return g.lower[a] + unit(rng) * (plane(g, a, g.res[a]) - g.lower[a]); };
  std::vector<Ray> rays;
  for (std::size_t i = 0; i < count; ++i) {
    glm::vec3 o, d;
    int kind = static_cast<int>(i % 6);
    for (int a = 0; a < 3; ++a) {
      o[a] = inside(a);
      d[a] = normal(rng);
    }
    if (kind == 0) {  // axis-parallel, on two cell planes (along a cell edge)
      int a = static_cast<int>(rng() % 3);
      d = glm::vec3(0.0f);
      d[a] = (rng() & 1) ? 1.0f : -1.0f;
      o[(a + 1) % 3] = plane_coord((a + 1) % 3);
      o[(a + 2) % 3] = plane_coord((a + 2) % 3);
      o[a] = d[a] > 0 ? g.lower[a] - 1.0f * g.cell[a] : plane(g, a, g.res[a]) + g.cell[a];
    } else if (kind == 1) {  // lying in one cell plane, oblique within it
      int a = static_cast<int>(rng() % 3);
      o[a] = plane_coord(a);
      d[a] = 0.0f;
    } else if (kind == 2) {  // starting on a grid corner (cell vertex)
      for (int a = 0; a < 3; ++a) o[a] = plane_coord(a);
    } else if (kind == 3) {  // diagonal through cell corners
      for (int a = 0; a < 3; ++a) {
        o[a] = plane_coord(a);
        d[a] = ((rng() & 1) ? 1.0f : -1.0f) * g.cell[a];
      }
    } else if (kind == 4) {  // from outside the grid towards a corner inside
      glm::vec3 target;
      for (int a = 0; a < 3; ++a) target[a] = plane_coord(a);
      for (int a = 0; a < 3; ++a) o[a] = target[a] + 3.0f * (plane(g, a, g.res[a]) - g.lower[a]) * normal(rng);
      d = target - o;
    }  // kind 5: inside, random direction
    if (d == glm::vec3(0.0f)) d.x = 1.0f;
    rays.push_back(make_ray(o, d));
  }
  return rays;
}

// Grid and brute force answer both queries identically: for closest hit
// the same hit / miss and t (bit for bit unless `level` is fast, where
// -cl-fast-relaxed-math may round differently in the two programs), for
// any hit the same hit / miss. At the robust level the closest hits are
// also judged against the double-precision reference.
void expect_grid_same_as_brute(const Geometry& g, const std::vector<Ray>& rays, const GridConfig& config,
                          Precision level, bool judge = true) {
  AccelConfig accel_config{level};
  auto brute = make_brute(test_device(), g, accel_config);
  auto grid = make_grid(test_device(), g, config, accel_config);
  for (Query q : {Query::closest, Query::any}) {
    SCOPED_TRACE(std::string(q == Query::closest ? "closest" : "any") + " at level " +
                 std::string(precision_name(level)) + " on " + g.source);
    auto expected = run_query(*brute, rays, q);
    auto hits = run_query(*grid, rays, q);
    std::size_t differ = 0;
    std::string first;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      bool same = (hits[i].prim < 0) == (expected[i].prim < 0);
      if (same && q == Query::closest && hits[i].prim >= 0)
        same = level == Precision::fast ? std::fabs(hits[i].t - expected[i].t) <= 1e-5f * std::fabs(expected[i].t)
                                        : hits[i].t == expected[i].t;
      if (!same && differ++ == 0) {
        const Ray& r = rays[i];
        first = "ray " + std::to_string(i) + " o=(" + std::to_string(r.ox) + "," + std::to_string(r.oy) + "," +
                std::to_string(r.oz) + ") d=(" + std::to_string(r.dx) + "," + std::to_string(r.dy) + "," +
                std::to_string(r.dz) + "): grid prim " + std::to_string(hits[i].prim) + " t " +
                std::to_string(hits[i].t) + ", brute prim " + std::to_string(expected[i].prim) + " t " +
                std::to_string(expected[i].t);
      }
    }
    EXPECT_EQ(differ, 0u) << "of " << rays.size() << " rays; first: " << first;
    if (judge && level == Precision::robust) {
      std::size_t failures = 0;
      auto report = judge_all(g, rays, hits, q, &failures);
      EXPECT_EQ(failures, 0u) << (report.empty() ? "" : report[0]);
    }
  }
}

GridConfig with_res(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  GridConfig c;
  c.resolution = {x, y, z};
  return c;
}

Geometry soup_with_spheres(std::size_t triangles, std::uint32_t seed) {
  Geometry g = random_soup(triangles, seed);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int i = 0; i < 20; ++i) g.spheres.push_back({glm::vec3(unit(rng), unit(rng), unit(rng)), 0.01f + 0.08f * unit(rng)});
  g.source = "soup with spheres";
  return g;
}

TEST(GridResolution, FollowsTheDensityAndTheBoxProportions) {
  GridResolution r = grid_resolution({4.0, 2.0, 1.0}, 1000, 8.0);  // 8000 cells: 40 x 20 x 10
  EXPECT_EQ(r, (GridResolution{40, 20, 10}));
  GridResolution cube = grid_resolution({1.0, 1.0, 1.0}, 1000, 1.0);
  EXPECT_EQ(cube, (GridResolution{10, 10, 10}));
}

TEST(GridResolution, FlatAxesGetOneCellAndTheOthersShareTheBudget) {
  EXPECT_EQ(grid_resolution({1.0, 1.0, 0.0}, 100, 1.0), (GridResolution{10, 10, 1}));
  EXPECT_EQ(grid_resolution({1.0, 0.0, 0.0}, 100, 1.0), (GridResolution{100, 1, 1}));
  EXPECT_EQ(grid_resolution({1.0, 1.0, 1e-9}, 100, 1.0), (GridResolution{10, 10, 1}));
  EXPECT_EQ(grid_resolution({0.0, 0.0, 0.0}, 100, 1.0), (GridResolution{1, 1, 1}));
  EXPECT_EQ(grid_resolution({1.0, 1.0, 1.0}, 1, 1e-6), (GridResolution{1, 1, 1}));
}

TEST(GridOverlap, SeparatingAxesAreExactAndTouchingCounts) {
  glm::dvec3 c(0.0), h(1.0);
  EXPECT_TRUE(triangle_box_overlap({-5, 0, 0}, {5, 0, 0}, {0, 5, 0}, c, h));   // cuts through
  EXPECT_TRUE(triangle_box_overlap({1, -3, -3}, {1, 3, -3}, {1, 0, 6}, c, h));  // in the face plane x = 1
  EXPECT_FALSE(triangle_box_overlap({1.0001, -3, -3}, {1.0001, 3, -3}, {1.0001, 0, 6}, c, h));
  // Its box overlaps the cube but its plane x + y = 2.5 passes beside the
  // edge x = y = 1: only the triangle normal separates.
  EXPECT_FALSE(triangle_box_overlap({2.5, 0, -5}, {0, 2.5, -5}, {1.25, 1.25, 5}, c, h));
  EXPECT_TRUE(triangle_box_overlap({2, 0, -5}, {0, 2, -5}, {1, 1, 5}, c, h));  // touches the edge x = y = 1
  EXPECT_TRUE(sphere_box_overlap({2.0, 0.0, 0.0}, 1.0, {-1, -1, -1}, {1, 1, 1}));
  EXPECT_FALSE(sphere_box_overlap({2.0, 2.0, 0.0}, 1.0, {-1, -1, -1}, {1, 1, 1}));
}

TEST(GridBuild, ListsEveryOverlappingCellAndOffsetsAreCompact) {
  Geometry g = soup_with_spheres(300, 5);
  Grid grid = build_grid(g, with_res(9, 7, 5));
  const GridHeader& h = grid.header;
  ASSERT_EQ(grid.cell_count(), 9u * 7u * 5u);
  EXPECT_EQ(grid.cell_begin.front(), 0u);
  EXPECT_EQ(grid.cell_begin.back(), grid.refs.size());
  EXPECT_TRUE(std::is_sorted(grid.cell_begin.begin(), grid.cell_begin.end()));
  // Brute-force check against the unwidened overlap test: listed whenever
  // it overlaps; within a cell, triangles ascending then spheres.
  for (int k = 0; k < h.res[2]; ++k)
    for (int j = 0; j < h.res[1]; ++j)
      for (int i = 0; i < h.res[0]; ++i) {
        std::size_t c = i + h.res[0] * (j + h.res[1] * k);
        std::vector<rtcl_i32> list(grid.refs.begin() + grid.cell_begin[c], grid.refs.begin() + grid.cell_begin[c + 1]);
        glm::dvec3 lo(plane(h, 0, i), plane(h, 1, j), plane(h, 2, k));
        glm::dvec3 hi(plane(h, 0, i + 1), plane(h, 1, j + 1), plane(h, 2, k + 1));
        for (std::size_t t = 0; t < g.triangles.size(); ++t) {
          const glm::uvec3& tri = g.triangles[t];
          bool overlaps = triangle_box_overlap(g.vertices[tri.x], g.vertices[tri.y], g.vertices[tri.z],
                                               0.5 * (lo + hi), 0.5 * (hi - lo));
          bool listed = std::find(list.begin(), list.end(), static_cast<rtcl_i32>(t)) != list.end();
          if (overlaps) EXPECT_TRUE(listed) << "triangle " << t << " cell " << c;
        }
        for (std::size_t s = 0; s < g.spheres.size(); ++s) {
          bool overlaps = sphere_box_overlap(g.spheres[s].center, g.spheres[s].radius, lo, hi);
          bool listed = std::find(list.begin(), list.end(), ~static_cast<rtcl_i32>(s)) != list.end();
          if (overlaps) EXPECT_TRUE(listed) << "sphere " << s << " cell " << c;
        }
        auto first_sphere = std::find_if(list.begin(), list.end(), [](rtcl_i32 r) { return r < 0; });
        EXPECT_TRUE(std::is_sorted(list.begin(), first_sphere));
        EXPECT_TRUE(std::all_of(first_sphere, list.end(), [](rtcl_i32 r) { return r < 0; }));
      }
}

TEST(GridBuild, MacrocellsOccupiedBoxesAndLanesFollowTheCellLists) {
  Geometry g = soup_with_spheres(300, 5);
  GridConfig config = with_res(9, 7, 5);
  config.macro = 2;
  Grid grid = build_grid(g, config);
  const GridHeader& h = grid.header;
  ASSERT_EQ(h.macro[3], 1);
  ASSERT_EQ(h.macro[0], 5);
  ASSERT_EQ(h.macro[1], 4);
  ASSERT_EQ(h.macro[2], 3);
  std::vector<int> expected_occupied(grid.occupied.size(), 0);
  auto inside = [](const float* rows, int lane, const glm::vec3& lo, const glm::vec3& hi) {
    for (int a = 0; a < 3; ++a)
      if (!(rows[a * 8 + lane] <= lo[a] && hi[a] <= rows[(3 + a) * 8 + lane])) return false;
    return true;
  };
  for (int k = 0; k < h.res[2]; ++k)
    for (int j = 0; j < h.res[1]; ++j)
      for (int i = 0; i < h.res[0]; ++i) {
        std::size_t c = i + h.res[0] * (j + h.res[1] * k);
        if (grid.cell_begin[c + 1] == grid.cell_begin[c]) continue;
        expected_occupied[(i >> 1) + h.macro[0] * ((j >> 1) + h.macro[1] * (k >> 1))] = 1;
        // The cell lies in the occupied box of its octant and of its sub-octant.
        glm::vec3 lo(plane(h, 0, i), plane(h, 1, j), plane(h, 2, k));
        glm::vec3 hi(plane(h, 0, i + 1), plane(h, 1, j + 1), plane(h, 2, k + 1));
        int octant = (i >= h.res[0] / 2) | (j >= h.res[1] / 2) << 1 | (k >= h.res[2] / 2) << 2;
        EXPECT_TRUE(inside(&h.occupied_bounds[0][0], octant, lo, hi)) << "cell " << c;
        bool in_sub = false;
        for (int sub = 0; sub < 8; ++sub) in_sub |= inside(&grid.occupied_boxes[octant * 48], sub, lo, hi);
        EXPECT_TRUE(in_sub) << "cell " << c;
      }
  for (std::size_t m = 0; m < grid.occupied.size(); ++m) EXPECT_EQ(grid.occupied[m], expected_occupied[m]) << m;
  // Lane k holds reference k's triangle; sphere references and the padding
  // past the last reference are NaN with id -1.
  const std::size_t stride = static_cast<std::size_t>(h.lane_stride);
  ASSERT_EQ(stride, grid.refs.size() + 8);
  std::vector<std::uint32_t> ids = stored_primitives(g);
  for (std::size_t k = 0; k < stride; ++k) {
    rtcl_i32 r = k < grid.refs.size() ? grid.refs[k] : -1;
    if (r < 0) {
      EXPECT_EQ(grid.lane_prims[k], -1);
      for (int row = 0; row < 9; ++row) EXPECT_TRUE(std::isnan(grid.lanes[row * stride + k]));
      continue;
    }
    std::uint32_t id = ids[static_cast<std::size_t>(r)];
    EXPECT_EQ(grid.lane_prims[k], static_cast<rtcl_i32>(id));
    const glm::uvec3& tri = g.triangles[id];
    for (int v = 0; v < 3; ++v)
      for (int a = 0; a < 3; ++a) EXPECT_EQ(grid.lanes[(3 * v + a) * stride + k], g.vertices[tri[v]][a]);
  }
}

TEST(GridBuild, TrianglesOnACellPlaneAreListedOnBothSides) {
  // Unit cube grid 4x4x4 over [0, 4]^3 (dyadic planes): a triangle in the
  // plane x = 2 belongs to the cells with i = 1 and i = 2.
  std::vector<float> xyz = {0, 0, 0, 4, 4, 4, 2, 0.5f, 0.5f, 2, 1.5f, 0.5f, 2, 0.5f, 1.5f, 0, 0, 4};
  std::vector<std::uint32_t> idx = {0, 1, 5, 2, 3, 4};
  Geometry g = Geometry::from_arrays(xyz.data(), 6, idx.data(), 2, "plane triangle");
  Grid grid = build_grid(g, with_res(4, 4, 4));
  int listed_i[4] = {0, 0, 0, 0};
  for (int i = 0; i < 4; ++i) {
    std::size_t c = i;  // j = k = 0
    for (std::uint32_t r = grid.cell_begin[c]; r < grid.cell_begin[c + 1]; ++r) listed_i[i] += grid.refs[r] == 1;
  }
  EXPECT_EQ(listed_i[1], 1);
  EXPECT_EQ(listed_i[2], 1);
}

TEST(GridBuild, FlatScenesGetCellsOfPositiveSize) {
  std::vector<float> xyz = {0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1};
  std::vector<std::uint32_t> idx = {0, 1, 2, 1, 3, 2};
  Geometry g = Geometry::from_arrays(xyz.data(), 4, idx.data(), 2, "flat quad");
  Grid grid = build_grid(g, {});
  EXPECT_EQ(grid.header.res[2], 1);
  for (int a = 0; a < 3; ++a) EXPECT_GT(grid.header.cell[a], 0.0f);
  EXPECT_LT(grid.header.lower[2], 1.0f);
  EXPECT_GT(plane(grid.header, 2, 1), 1.0f);
}

TEST(GridBuild, AnAutomaticResolutionKeepsTheReferenceBudget) {
  const int n = 5000;
  Geometry g = triangle_fan(n);
  GridConfig unbounded;
  unbounded.max_references_per_triangle = std::numeric_limits<double>::infinity();
  Grid dense = build_grid(g, unbounded);
  double dense_refs = static_cast<double>(dense.refs.size()) / n;
  ASSERT_GT(dense_refs, GridConfig{}.max_references_per_triangle) << "the fan no longer exceeds the budget";
  Grid budgeted = build_grid(g, {});
  double refs = static_cast<double>(budgeted.refs.size()) / n;
  // The budget is checked on a sample of 1024 of the triangles: the whole
  // list may exceed it by the sample's error (the fan's slivers all have
  // the same length, so a small one).
  EXPECT_LE(refs, 1.1 * GridConfig{}.max_references_per_triangle);
  EXPECT_LT(std::size_t(budgeted.header.res[0]) * budgeted.header.res[1],
            std::size_t(dense.header.res[0]) * dense.header.res[1]);
  // An explicit resolution is kept as given.
  GridConfig explicit_res = unbounded;
  explicit_res.max_references_per_triangle = 1.0;
  explicit_res.resolution = {dense.header.res[0] + 0u, dense.header.res[1] + 0u, 1u};
  EXPECT_EQ(build_grid(g, explicit_res).refs.size(), dense.refs.size());
}

TEST(GridBuild, BadConfigAndDeviceLimitsAreErrorsNamingTheOption) {
  Geometry g = random_soup(100, 3);
  GridConfig bad;
  bad.lambda = -1.0;
  EXPECT_THROW(build_grid(g, bad), Error);
  try {
    build_grid(g, bad);
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("lambda must be > 0"), std::string::npos) << e.what();
  }
  EXPECT_THROW(build_grid(g, with_res(4, 0, 4)), Error);
  GridConfig small = with_res(64, 64, 64);
  small.max_alloc_bytes = 1 << 16;
  try {
    build_grid(g, small);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    std::string m = e.what();
    EXPECT_NE(m.find("res=64x64x64"), std::string::npos) << m;
    EXPECT_NE(m.find("CL_DEVICE_MAX_MEM_ALLOC_SIZE"), std::string::npos) << m;
  }
  GridConfig refs = with_res(2, 2, 2);
  refs.max_alloc_bytes = 64;  // offsets fit, 100+ references do not
  EXPECT_THROW(build_grid(g, refs), Error);
}

TEST(GridTrace, MatchesBruteForceOnSoupsAtEveryLevel) {
  Geometry g = soup_with_spheres(2000, 11);
  std::vector<Ray> rays = random_rays(g, 1500, 12);
  for (Precision level : kLevels) expect_grid_same_as_brute(g, rays, {}, level);
}

TEST(GridTrace, MatchesBruteForceOnCellBoundaryRays) {
  Geometry g = soup_with_spheres(1500, 21);
  for (GridResolution res : {GridResolution{1, 1, 1}, GridResolution{4, 4, 4}, GridResolution{7, 3, 11},
                             GridResolution{96, 96, 96}}) {
    GridConfig config = with_res(res[0], res[1], res[2]);
    std::vector<Ray> rays = cell_boundary_rays(build_grid(g, config), 22, 3000);
    for (Precision level : kLevels) expect_grid_same_as_brute(g, rays, config, level);
  }
}

TEST(GridTrace, EveryMacrocellSizeMatchesBruteForceOnASparseScene) {
  // Small triangles in a few clusters, so that rays cross empty macrocells
  // and enter occupied ones through their faces, edges and corners.
  Geometry g;
  g.source = "clustered soup";
  std::mt19937 rng(41);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const glm::vec3 centres[] = {{0.1f, 0.1f, 0.1f}, {0.9f, 0.5f, 0.2f}, {0.5f, 0.9f, 0.9f}, {0.2f, 0.8f, 0.4f}};
  for (const glm::vec3& centre : centres)
    for (int t = 0; t < 150; ++t) {
      glm::vec3 c = centre + 0.08f * glm::vec3(unit(rng) - 0.5f, unit(rng) - 0.5f, unit(rng) - 0.5f);
      std::uint32_t b = static_cast<std::uint32_t>(g.vertices.size());
      for (int v = 0; v < 3; ++v)
        g.vertices.push_back(c + 0.02f * glm::vec3(unit(rng) - 0.5f, unit(rng) - 0.5f, unit(rng) - 0.5f));
      g.triangles.push_back({b, b + 1, b + 2});
    }
  g.spheres.push_back({glm::vec3(0.8f, 0.2f, 0.8f), 0.05f});
  for (unsigned macro : {1u, 2u, 8u}) {
    GridConfig config = with_res(40, 24, 32);
    config.macro = macro;
    std::vector<Ray> rays = cell_boundary_rays(build_grid(g, config), 42 + macro, 3000);
    for (Precision level : {Precision::robust, Precision::exact}) expect_grid_same_as_brute(g, rays, config, level);
  }
}

TEST(GridTrace, DyadicSceneRaysOnCellPlanesAndCorners) {
  // Grid planes fall on the cubes' faces of cube_grid-like geometry: a 4x4x4
  // grid over quads at x = 0.5, 1.5, ... seen along cell edges.
  std::vector<float> xyz;
  std::vector<std::uint32_t> idx;
  for (int q = 0; q < 4; ++q) {
    float x = 0.5f + q;
    std::uint32_t b = static_cast<std::uint32_t>(xyz.size() / 3);
    for (float v : {x, 0.0f, 0.0f, x, 4.0f, 0.0f, x, 0.0f, 4.0f, x, 4.0f, 4.0f}) xyz.push_back(v);
    for (std::uint32_t v : {b, b + 1, b + 2, b + 1, b + 3, b + 2}) idx.push_back(v);
  }
  Geometry g = Geometry::from_arrays(xyz.data(), xyz.size() / 3, idx.data(), idx.size() / 3, "dyadic quads");
  GridConfig config = with_res(8, 4, 4);
  std::vector<Ray> rays = cell_boundary_rays(build_grid(g, config), 31, 2000);
  for (int y = 0; y <= 4; ++y)
    for (int z = 0; z <= 4; ++z) {
      rays.push_back(make_ray({-1.0f, float(y), float(z)}, {1, 0, 0}));
      rays.push_back(make_ray({5.0f, float(y), float(z)}, {-1, 0, 0}));
      rays.push_back(make_ray({0.5f, float(y), float(z)}, {1, 0, 0}));  // starts on a surface, on a cell plane
      rays.push_back(make_ray({1.0f, float(y), float(z)}, {1, 1, 1}));  // from a grid corner
    }
  for (Precision level : kLevels) expect_grid_same_as_brute(g, rays, config, level);
}

TEST(GridTrace, FlatSceneSingleTriangleAndTinyIntervals) {
  std::vector<float> xyz = {0, 0, 1, 1, 0, 1, 0, 1, 1};
  std::vector<std::uint32_t> idx = {0, 1, 2};
  Geometry one = Geometry::from_arrays(xyz.data(), 3, idx.data(), 1, "single triangle");
  std::vector<Ray> rays = random_rays(one, 500, 3);
  rays.push_back(make_ray({0.25f, 0.25f, 0.0f}, {0, 0, 1}));
  rays.push_back(make_ray({0.25f, 0.25f, 2.0f}, {0, 0, -1}));
  rays.push_back(make_ray({0.25f, 0.25f, 1.0f}, {0, 0, 1}));  // origin on the surface
  rays.push_back(make_ray({-1.0f, 0.25f, 1.0f}, {1, 0, 0}));  // in the plane: no hit
  rays.push_back(make_ray({0.25f, 0.25f, 0.0f}, {0, 0, 1}, 0.0f, 1.0f));  // tmax exactly at the hit
  rays.push_back(make_ray({0.25f, 0.25f, 0.0f}, {0, 0, 1}, 0.0f, std::nextafter(1.0f, 0.0f)));
  for (Precision level : kLevels) {
    expect_grid_same_as_brute(one, rays, {}, level);
    expect_grid_same_as_brute(one, rays, with_res(1, 1, 1), level);
  }
  Geometry flat = random_soup(500, 8);
  for (auto& v : flat.vertices) v.z = 0.5f;
  for (auto& t : flat.triangles) (void)t;
  flat.source = "flat soup";
  std::vector<Ray> flat_rays = random_rays(flat, 1000, 9);
  for (Precision level : kLevels) expect_grid_same_as_brute(flat, flat_rays, {}, level);
}

TEST(GridTrace, MatchesBruteForceAndReferenceOnTheBunny) {
  Geometry g = load_mesh(scene_path("stanford_bunny/bunny.obj")).geometry;
  validate(g);
  std::vector<Ray> rays = random_rays(g, 1500, 41);
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  Aabb box = g.bounds();
  for (int i = 0; i < 1500; ++i) {  // interior views
    glm::vec3 o = box.lower + box.extent() * glm::vec3(unit(rng), unit(rng), unit(rng));
    rays.push_back(make_ray(o, {normal(rng), normal(rng), normal(rng)}));
  }
  std::vector<Ray> boundary = cell_boundary_rays(build_grid(g, {}), 43, 1500);
  rays.insert(rays.end(), boundary.begin(), boundary.end());
  for (Precision level : kLevels) expect_grid_same_as_brute(g, rays, {}, level, /*judge=*/false);
  GridConfig fine;
  fine.lambda = 64.0;
  expect_grid_same_as_brute(g, rays, fine, Precision::robust, false);
  // The reference judge (O(triangles) per ray) on a subset.
  std::vector<Ray> some(rays.begin(), rays.begin() + 300);
  some.insert(some.end(), rays.end() - 300, rays.end());
  std::vector<Hit> references = reference_closest_all(g, some);
  auto grid = make_grid(test_device(), g);
  for (Query q : {Query::closest, Query::any}) {
    std::size_t failures = 0;
    auto report = judge_all(g, some, run_query(*grid, some, q), q, references, &failures);
    EXPECT_EQ(failures, 0u) << (report.empty() ? "" : report[0]);
  }
}

TEST(GridTrace, ReportsStats) {
  Geometry g = random_soup(1000, 4);
  auto grid = make_grid(test_device(), g, with_res(10, 10, 10));
  EXPECT_EQ(grid->name(), "grid");
  EXPECT_EQ(grid->stats().node_count, 1000u);
  EXPECT_EQ(grid->stats().primitive_count, 1000u);
  Grid host = build_grid(g, with_res(10, 10, 10));
  EXPECT_EQ(grid->stats().device_bytes, host.bytes());
}

}  // namespace
}  // namespace rtcl::test
