// The octrees (src/rtcl/accel/octree*.cpp, kernels/accel/octree*.cl): node
// codes that round-trip, bad options refused before any work, the code
// table's invariants, and answers identical to brute force (same primitive
// and t, bit for bit at the robust and exact levels) for octree, octree-ptr
// and octree-r on soups, the bunny and rays along split planes, through
// cell corners and edges, starting on boundaries and inside the scene,
// axis-parallel with ±0, at the deepest depth each representation holds,
// and on a flat scene.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "rtcl/accel/brute.hpp"
#include "rtcl/accel/octree.hpp"
#include "rtcl/accel/octree_ptr.hpp"
#include "rtcl/accel/octree_r.hpp"
#include "rtcl/bounds/clip.hpp"
#include "rtcl/error.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/error_of.hpp"
#include "support/fixtures.hpp"
#include "support/reference.hpp"

namespace rtcl::test {
namespace {

const std::vector<std::string> kOctrees = {"octree", "octree-ptr", "octree-r"};


std::string describe(const Ray& r, const Hit& got, const Hit& want) {
  return "o=(" + std::to_string(r.ox) + "," + std::to_string(r.oy) + "," + std::to_string(r.oz) + ") d=(" +
         std::to_string(r.dx) + "," + std::to_string(r.dy) + "," + std::to_string(r.dz) + "): prim " +
         std::to_string(got.prim) + " t " + std::to_string(got.t) + ", brute prim " + std::to_string(want.prim) +
         " t " + std::to_string(want.t);
}

// Each of `specs` (e.g. "octree:depth=4") and brute force answer both
// queries alike: closest hits with the same primitive and t (bit for bit
// unless fast), any hits with the same hit / miss.
void expect_octrees_same_as_brute(const Geometry& g, const std::vector<Ray>& rays, const std::vector<std::string>& specs,
                          Precision level) {
  AccelConfig config{level};
  auto brute = make_brute(test_device(), g, config);
  for (Query q : {Query::closest, Query::any}) {
    auto want = run_query(*brute, rays, q);
    for (const std::string& spec : specs) {
      SCOPED_TRACE(spec + (q == Query::closest ? " closest" : " any") + " at " +
                   std::string(precision_name(level)) + " on " + g.source);
      auto got = run_query(*make_accel(test_device(), spec, g, config), rays, q);
      std::size_t differ = 0;
      std::string first;
      for (std::size_t i = 0; i < rays.size(); ++i) {
        bool same = (got[i].prim < 0) == (want[i].prim < 0);
        if (same && q == Query::closest && got[i].prim >= 0)
          same = level == Precision::fast ? std::fabs(got[i].t - want[i].t) <= 1e-5f * std::fabs(want[i].t)
                                          : got[i].t == want[i].t && got[i].prim == want[i].prim;
        if (!same && differ++ == 0) first = "ray " + std::to_string(i) + " " + describe(rays[i], got[i], want[i]);
      }
      EXPECT_EQ(differ, 0u) << "of " << rays.size() << " rays; first: " << first;
    }
  }
}

// Rays aimed at the planes `planes[a]` (split planes of a tree): along
// them, in them, through their crossings (cell edges and corners), from
// them, axis-parallel with +0 and -0 components, from outside and inside.
std::vector<Ray> plane_rays(const std::array<std::vector<float>, 3>& planes, const Geometry& g, std::uint32_t seed,
                            std::size_t count) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  Aabb box = g.bounds();
  auto on_plane = [&](int a) { return planes[a][rng() % planes[a].size()]; };
  auto inside = [&](int a) { return box.lower[a] + unit(rng) * (box.upper[a] - box.lower[a]); };
  std::vector<Ray> rays;
  for (std::size_t i = 0; i < count; ++i) {
    glm::vec3 o, d;
    for (int a = 0; a < 3; ++a) {
      o[a] = inside(a);
      d[a] = normal(rng);
    }
    int a = static_cast<int>(rng() % 3), b = (a + 1) % 3, c = (a + 2) % 3;
    float zero = (rng() & 1) ? 0.0f : -0.0f;
    switch (i % 7) {
      case 0:  // axis-parallel along a cell edge, from outside
        d = glm::vec3(zero);
        d[a] = (rng() & 1) ? 1.0f : -1.0f;
        o[b] = on_plane(b);
        o[c] = on_plane(c);
        o[a] = d[a] > 0 ? box.lower[a] - 1.0f : box.upper[a] + 1.0f;
        break;
      case 1:  // in a split plane, oblique within it
        o[a] = on_plane(a);
        d[a] = zero;
        break;
      case 2:  // from a cell corner
        for (int k = 0; k < 3; ++k) o[k] = on_plane(k);
        break;
      case 3: {  // from outside through a corner
        glm::vec3 target(on_plane(0), on_plane(1), on_plane(2));
        for (int k = 0; k < 3; ++k) o[k] = target[k] + 3.0f * (box.upper[k] - box.lower[k]) * normal(rng);
        d = target - o;
        break;
      }
      case 4:  // diagonal along cell corners
        for (int k = 0; k < 3; ++k) {
          o[k] = on_plane(k);
          d[k] = (rng() & 1) ? 1.0f : -1.0f;
        }
        break;
      case 5:  // axis-parallel from inside, starting on a plane
        d = glm::vec3(zero);
        d[a] = (rng() & 1) ? 1.0f : -1.0f;
        o[a] = on_plane(a);
        break;
      default:  // inside, random direction
        break;
    }
    if (d == glm::vec3(0.0f)) d.x = 1.0f;
    rays.push_back(make_ray(o, d));
  }
  return rays;
}

// The lattice planes of a depth-n cube down to level `levels`.
std::array<std::vector<float>, 3> lattice_planes(const Geometry& g, int depth, int levels) {
  OctreeHeader cube = octree_cube(g, depth);
  std::array<std::vector<float>, 3> planes;
  std::uint32_t stride = 1u << (depth - std::min(depth, levels));
  for (int a = 0; a < 3; ++a)
    for (std::uint64_t n = 0; n <= (std::uint64_t(1) << depth); n += stride)
      planes[a].push_back(cube.lower[a] + static_cast<float>(n) * cube.cell);
  return planes;
}

// The split planes of an Octree-R tree, and its box.
std::array<std::vector<float>, 3> split_planes(const OctreePtr& tree) {
  std::array<std::vector<float>, 3> planes;
  for (int a = 0; a < 3; ++a) {
    planes[a] = {tree.header.lower[a], tree.header.upper[a]};
    for (const OctreeNode& n : tree.nodes) planes[a].push_back(n.split[a]);
  }
  return planes;
}

Geometry soup_with_16_spheres(std::size_t triangles, std::uint32_t seed) {
  Geometry g = random_soup(triangles, seed);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int i = 0; i < 16; ++i)
    g.spheres.push_back({glm::vec3(unit(rng), unit(rng), unit(rng)), 0.01f + 0.06f * unit(rng)});
  g.source = "soup with spheres";
  return g;
}

TEST(OctreeCode, PointCodeLowerCornerRoundTripsAtEveryDepth) {
  std::mt19937 rng(5);
  for (int depth = 0; depth <= RTCL_OCTREE_MAX_DEPTH; ++depth) {
    std::uint32_t side = 1u << depth;
    for (int trial = 0; trial < 50; ++trial) {
      std::array<std::uint32_t, 3> p{std::uint32_t(rng() % side), std::uint32_t(rng() % side), std::uint32_t(rng() % side)};
      if (trial == 0) p = {side - 1, side - 1, side - 1};
      std::uint64_t q = octree_point_code(p, depth);
      for (int l = 1; l <= depth; ++l)  // property 1, digit by digit
        ASSERT_EQ((q >> (4 * (depth - l))) & 0xf, ((p[0] >> (depth - l)) & 1) + 2 * ((p[1] >> (depth - l)) & 1) +
                                                       4 * ((p[2] >> (depth - l)) & 1));
      for (int level = 0; level <= depth; ++level) {
        std::uint64_t code = octree_node_code(q, level, depth);
        std::uint32_t mask = ~((1u << (depth - level)) - 1u);
        std::array<std::uint32_t, 3> corner = octree_lower_corner(code, level, depth);
        ASSERT_EQ(corner, (std::array<std::uint32_t, 3>{p[0] & mask, p[1] & mask, p[2] & mask}))
            << "depth " << depth << " level " << level;
        for (int l = level + 1; l <= depth; ++l) ASSERT_EQ((code >> (4 * (depth - l))) & 0xf, 0xfu);
      }
    }
  }
}

TEST(OctreeBuild, TableIsSortedBucketedAndListsEveryPrimitive) {
  Geometry g = soup_with_16_spheres(800, 3);
  for (bool buckets : {true, false}) {
    OctreeConfig config;
    config.max_depth = 6;
    config.buckets = buckets;
    Octree tree = build_octree(g, config);
    ASSERT_GT(tree.codes.size(), 8u);
    EXPECT_TRUE(std::is_sorted(tree.codes.begin(), tree.codes.end()));
    EXPECT_EQ(tree.header.top_digits > 0, buckets);
    EXPECT_EQ(tree.bucket_begin.size(), (std::size_t(1) << (3 * tree.header.top_digits)) + 1);
    EXPECT_TRUE(std::is_sorted(tree.bucket_begin.begin(), tree.bucket_begin.end()));
    ASSERT_EQ(tree.leaf_begin.size(), 2 * tree.codes.size() + 2);
    EXPECT_EQ(tree.leaf_begin[tree.leaf_begin.size() - 2], tree.blocks.triangles.size());
    EXPECT_EQ(tree.leaf_begin.back(), tree.blocks.spheres.size());
    std::vector<int> seen(g.primitive_count(), 0);
    std::size_t copies = 0;
    for (const TriangleBlock& b : tree.blocks.triangles)
      for (rtcl_i32 p : b.prim) copies += p >= 0 && ++seen[std::size_t(p)] > 0;
    for (const SphereBlock& b : tree.blocks.spheres)
      for (rtcl_i32 p : b.prim) copies += p >= 0 && ++seen[std::size_t(p)] > 0;
    EXPECT_EQ(std::count(seen.begin(), seen.end(), 0), 0) << "a primitive in no leaf";
    EXPECT_EQ(copies, tree.ref_count);
  }
}

// The pointer octrees' boxes: walking the tree from the root box through
// the split planes, the part of each leaf triangle inside the leaf's cell
// (clipped in double, an independent computation) lies in its block's
// BlockBox and in the occupied box of the root child above the leaf, and so
// does each leaf sphere's box within the cell.
TEST(OctreeBuild, BlockBoxesAndOccupiedBoundsHoldWhatTheLeavesHold) {
  Geometry g = soup_with_16_spheres(600, 11);
  for (bool cost : {false, true}) {
    SCOPED_TRACE(cost ? "octree-r" : "octree-ptr");
    OctreePtr tree = cost ? build_octree_r(g) : build_octree_ptr(g);
    ASSERT_EQ(tree.block_boxes.size(), tree.blocks.triangles.size());
    auto inside = [](const glm::dvec3& lo, const glm::dvec3& hi, const float* b) {
      for (int a = 0; a < 3; ++a)
        if (lo[a] < double(b[a]) || hi[a] > double(b[3 + a])) return false;
      return true;
    };
    struct Visit {
      rtcl_i32 ref;
      glm::dvec3 lo, hi;
      int octant;
    };
    glm::dvec3 root_lo(tree.header.lower[0], tree.header.lower[1], tree.header.lower[2]);
    glm::dvec3 root_hi(tree.header.upper[0], tree.header.upper[1], tree.header.upper[2]);
    std::vector<Visit> todo = {{tree.header.root, root_lo, root_hi, 0}};
    std::size_t checked = 0;
    while (!todo.empty()) {
      Visit v = todo.back();
      todo.pop_back();
      if (v.ref == RTCL_CHILD_EMPTY) continue;
      if (v.ref >= 0) {
        const OctreeNode& n = tree.nodes[std::size_t(v.ref)];
        for (int q = 0; q < 8; ++q) {
          glm::dvec3 lo = v.lo, hi = v.hi;
          for (int a = 0; a < 3; ++a) ((q >> a) & 1 ? lo[a] : hi[a]) = n.split[a];
          todo.push_back({n.child[q], lo, hi, v.ref == tree.header.root ? q : v.octant});
        }
        continue;
      }
      std::array<float, 6> occupied;
      for (int r = 0; r < 6; ++r) occupied[std::size_t(r)] = tree.header.occupied_bounds[r][v.octant];
      auto leaf = std::size_t(~v.ref);
      for (rtcl_u32 b = tree.leaf_begin[2 * leaf]; b < tree.leaf_begin[2 * leaf + 2]; ++b) {
        const TriangleBlock& block = tree.blocks.triangles[b];
        for (int l = 0; l < RTCL_BLOCK_WIDTH; ++l) {
          if (block.prim[l] < 0) continue;
          glm::dvec3 p[3];
          for (int k = 0; k < 3; ++k) p[k] = glm::dvec3(block.v[k][0][l], block.v[k][1][l], block.v[k][2][l]);
          glm::dvec3 lo, hi;
          if (!clip_triangle_bounds(p[0], p[1], p[2], v.lo, v.hi, &lo, &hi)) continue;
          EXPECT_TRUE(inside(lo, hi, tree.block_boxes[b].bounds)) << "prim " << block.prim[l] << " block " << b;
          EXPECT_TRUE(inside(lo, hi, occupied.data())) << "prim " << block.prim[l] << " octant " << v.octant;
          ++checked;
        }
      }
      for (rtcl_u32 b = tree.leaf_begin[2 * leaf + 1]; b < tree.leaf_begin[2 * leaf + 3]; ++b) {
        const SphereBlock& block = tree.blocks.spheres[b];
        for (int l = 0; l < RTCL_BLOCK_WIDTH; ++l) {
          if (block.prim[l] < 0) continue;
          glm::dvec3 c(block.cx[l], block.cy[l], block.cz[l]);
          glm::dvec3 lo = glm::max(c - double(block.r[l]), v.lo), hi = glm::min(c + double(block.r[l]), v.hi);
          if (glm::any(glm::greaterThan(lo, hi))) continue;
          EXPECT_TRUE(inside(lo, hi, occupied.data())) << "sphere " << block.prim[l] << " octant " << v.octant;
          ++checked;
        }
      }
    }
    EXPECT_GT(checked, 600u);
  }
}

TEST(OctreeBuild, BadOptionsAreErrorsNamingTheStructureAndOption) {
  Geometry g = random_soup(200, 3);
  OctreeConfig deep;
  deep.max_depth = RTCL_OCTREE_MAX_DEPTH + 1;
  EXPECT_NE(error_of([&] { build_octree(g, deep); }).find("octree: depth=17: must be in [0, 16]"),
            std::string::npos);
  OctreeConfig empty_leaf;
  empty_leaf.leaf_size = 0;
  EXPECT_NE(error_of([&] { build_octree(g, empty_leaf); }).find("octree: leaf_size=0"), std::string::npos);
  OctreePtrConfig ptr;
  ptr.max_depth = kOctreePtrMaxDepth + 1;
  EXPECT_NE(error_of([&] { build_octree_ptr(g, ptr); }).find("octree-ptr: depth=21"), std::string::npos);
  OctreeRConfig bins;
  bins.bins = 1;
  EXPECT_NE(error_of([&] { build_octree_r(g, bins); }).find("octree-r: bins=1"), std::string::npos);
  for (const char* spec : {"octree:depth=17", "octree-ptr:leaf_size=0", "octree-r:depth=-1"}) {
    std::string e = error_of([&] { make_accel(test_device(), spec, g); });
    EXPECT_EQ(e.rfind("make_accel name \"" + std::string(spec) + "\": ", 0), 0u) << e;
  }
  OctreeConfig small;
  small.max_alloc_bytes = 256;  // fewer references than the soup's 200 triangles
  std::string e = error_of([&] { build_octree(g, small); });
  EXPECT_NE(e.find("octree over"), std::string::npos) << e;
  EXPECT_NE(e.find("CL_DEVICE_MAX_MEM_ALLOC_SIZE"), std::string::npos) << e;
  OctreeRConfig small_r;
  small_r.max_alloc_bytes = 256;
  EXPECT_NE(error_of([&] { build_octree_r(g, small_r); }).find("octree-r over"), std::string::npos);
}

TEST(OctreeBuild, OctreeRChoosesPlanesByCost) {
  // Primitives crowded in [0, 0.1] of [0, 1]: the plane follows them.
  std::vector<double> lo, hi;
  for (int i = 0; i < 100; ++i) {
    lo.push_back(0.001 * i);
    hi.push_back(0.001 * i + 0.0005);
  }
  float p = octree_r_split(0.0, 1.0, 1.0, 1.0, lo, hi, 16);
  EXPECT_LT(p, 0.2f);
  EXPECT_GT(p, 0.0f);
  EXPECT_EQ(octree_r_split(0.0, 0.0, 1.0, 1.0, lo, hi, 16), 0.0f);  // a flat node: its only plane
}

TEST(OctreeTrace, MatchesBruteForceOnSoupsAtEveryLevel) {
  Geometry g = soup_with_16_spheres(1500, 11);
  std::vector<Ray> rays = random_rays(g, 800, 12);
  std::vector<Ray> planes = plane_rays(lattice_planes(g, 10, 5), g, 13, 1400);
  rays.insert(rays.end(), planes.begin(), planes.end());
  for (Precision level : test_precisions()) expect_octrees_same_as_brute(g, rays, kOctrees, level);
}

// Separate tiny triangles: a cluster 2^-15 across in a unit scene, which
// only the deepest trees resolve, and two large parallel ones around it.
Geometry tiny_cluster() {
  std::vector<float> xyz;
  std::vector<std::uint32_t> idx;
  auto triangle = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c) {
    std::uint32_t base = static_cast<std::uint32_t>(xyz.size() / 3);
    for (const glm::vec3& v : {a, b, c}) xyz.insert(xyz.end(), {v.x, v.y, v.z});
    idx.insert(idx.end(), {base, base + 1, base + 2});
  };
  const float step = 1.0f / 65536.0f;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) {
        glm::vec3 o = glm::vec3(0.3f) + step * glm::vec3(i, j, k);
        triangle(o, o + glm::vec3(0.5f * step, 0, 0), o + glm::vec3(0, 0.5f * step, 0.25f * step));
      }
  triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  triangle({0, 0, 1}, {1, 0, 1}, {0, 1, 1});  // parallel to the first: no intersection line to resolve
  return Geometry::from_arrays(xyz.data(), xyz.size() / 3, idx.data(), idx.size() / 3, "tiny cluster");
}

TEST(OctreeTrace, MatchesBruteForceOnSplitPlaneRaysOfEveryShape) {
  Geometry g = soup_with_16_spheres(1000, 21);
  for (int depth : {0, 3}) {  // one leaf; shallow and coarse
    std::vector<Ray> rays = plane_rays(lattice_planes(g, depth, 6), g, 22 + depth, 1400);
    std::string options = ":depth=" + std::to_string(depth) + ",leaf_size=4";
    expect_octrees_same_as_brute(g, rays, {"octree" + options, "octree-ptr" + options}, Precision::robust);
  }
  OctreeRConfig r;
  r.leaf_size = 2;
  std::vector<Ray> rays = plane_rays(split_planes(build_octree_r(g, r)), g, 41, 1400);
  expect_octrees_same_as_brute(g, rays, {"octree-r:leaf_size=2", "octree-r:depth=5,leaf_size=1,bins=4"}, Precision::robust);
}

TEST(OctreeTrace, TheDeepestTreesMatchBruteForce) {
  Geometry g = tiny_cluster();
  std::mt19937 rng(7);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  std::vector<Ray> rays = plane_rays(lattice_planes(g, 16, 16), g, 50, 600);
  for (int i = 0; i < 600; ++i) {  // at the cluster, from afar and from within
    glm::vec3 target = glm::vec3(0.3f) + (4.0f / 65536.0f) * glm::vec3(normal(rng), normal(rng), normal(rng));
    glm::vec3 d(normal(rng), normal(rng), normal(rng));
    rays.push_back(make_ray(i % 2 ? target - d : target, d));
  }
  OctreeConfig config;
  config.max_depth = RTCL_OCTREE_MAX_DEPTH;
  config.leaf_size = 1;
  Octree tree = build_octree(g, config);
  std::size_t deepest = 0;
  for (std::uint64_t c : tree.codes) deepest += (c & 0xf) != 0xf;  // a last digit that is not F: level 16
  EXPECT_GT(deepest, 0u);
  expect_octrees_same_as_brute(g, rays,
                       {"octree:depth=16,leaf_size=1", "octree:depth=16,leaf_size=1,buckets=false",
                        "octree-ptr:depth=20,leaf_size=1", "octree-r:depth=20,leaf_size=1"},
                       Precision::robust);
}

TEST(OctreeTrace, DyadicQuadsSeenAlongCellEdges) {
  // Quads across each axis at 0.5, 1.5, 2.5: on lattice planes of the
  // depth-4 cube over [0, 4]^3 (up to its padding), seen along cell edges.
  std::vector<float> xyz;
  std::vector<std::uint32_t> idx;
  for (int axis = 0; axis < 3; ++axis)
    for (float at : {0.5f, 1.5f, 2.5f}) {
      std::uint32_t base = static_cast<std::uint32_t>(xyz.size() / 3);
      for (int corner = 0; corner < 4; ++corner) {
        float p[3];
        p[axis] = at;
        p[(axis + 1) % 3] = corner & 1 ? 4.0f : 0.0f;
        p[(axis + 2) % 3] = corner & 2 ? 4.0f : 0.0f;
        xyz.insert(xyz.end(), p, p + 3);
      }
      idx.insert(idx.end(), {base, base + 1, base + 2, base + 1, base + 3, base + 2});
    }
  Geometry g = Geometry::from_arrays(xyz.data(), xyz.size() / 3, idx.data(), idx.size() / 3, "dyadic quads");
  std::vector<Ray> rays = plane_rays(lattice_planes(g, 4, 4), g, 31, 700);
  for (int y = 0; y <= 4; ++y)
    for (int z = 0; z <= 4; ++z) {
      rays.push_back(make_ray({-1.0f, float(y), float(z)}, {1, 0, 0}));
      rays.push_back(make_ray({5.0f, float(y), float(z)}, {-1, -0.0f, 0}));
      rays.push_back(make_ray({0.5f, float(y), float(z)}, {1, 0, 0}));  // starts on a surface
      rays.push_back(make_ray({1.0f, float(y), float(z)}, {1, 1, 1}));  // from a corner
    }
  for (Precision level : test_precisions())
    expect_octrees_same_as_brute(g, rays, {"octree:depth=4,leaf_size=1", "octree-ptr:depth=4,leaf_size=1", "octree-r:leaf_size=1"},
                         level);
}

TEST(OctreeTrace, FlatSceneAndTinyIntervals) {
  Geometry flat = random_soup(400, 8);
  for (auto& v : flat.vertices) v.z = 0.5f;
  flat.source = "flat soup";
  std::vector<Ray> rays = random_rays(flat, 600, 9);
  rays.push_back(make_ray({0.25f, 0.25f, 0.0f}, {0, 0, 1}));
  rays.push_back(make_ray({0.25f, 0.25f, 0.0f}, {0, 0, 1}, 0.0f, 0.5f));  // tmax exactly at the plane
  rays.push_back(make_ray({0.25f, 0.25f, 0.0f}, {0, 0, 1}, 0.0f, std::nextafter(0.5f, 0.0f)));
  rays.push_back(make_ray({-1.0f, 0.25f, 0.5f}, {1, 0, 0}));  // in the plane
  expect_octrees_same_as_brute(flat, rays, kOctrees, Precision::robust);
}

TEST(OctreeTrace, MatchesBruteForceAndReferenceOnTheBunny) {
  Geometry g = load_mesh(scene_path("stanford_bunny/bunny.obj")).geometry;
  validate(g);
  std::vector<Ray> rays = random_rays(g, 700, 41);
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  Aabb box = g.bounds();
  for (int i = 0; i < 500; ++i) {  // interior views
    glm::vec3 o = box.lower + box.extent() * glm::vec3(unit(rng), unit(rng), unit(rng));
    rays.push_back(make_ray(o, {normal(rng), normal(rng), normal(rng)}));
  }
  std::vector<Ray> planes = plane_rays(lattice_planes(g, 10, 6), g, 43, 500);
  rays.insert(rays.end(), planes.begin(), planes.end());
  expect_octrees_same_as_brute(g, rays, kOctrees, Precision::robust);
  std::vector<Ray> some(rays.begin(), rays.begin() + 150);
  some.insert(some.end(), rays.end() - 150, rays.end());
  std::vector<Hit> references = reference_closest_all(g, some);
  for (const std::string& name : kOctrees) {
    auto accel = make_accel(test_device(), name, g);
    for (Query q : {Query::closest, Query::any}) {
      std::size_t failures = 0;
      auto report = judge_all(g, some, run_query(*accel, some, q), q, references, &failures);
      EXPECT_EQ(failures, 0u) << name << ": " << (report.empty() ? "" : report[0]);
    }
  }
}

TEST(OctreeTrace, ReportsStats) {
  Geometry g = random_soup(1000, 4);
  for (const std::string& name : kOctrees) {
    auto accel = make_accel(test_device(), name, g);
    EXPECT_EQ(accel->name(), name);
    EXPECT_EQ(accel->stats().primitive_count, 1000u);
    EXPECT_GT(accel->stats().node_count, 1u);
  }
  OctreeConfig config;
  EXPECT_EQ(make_octree(test_device(), g, config)->stats().device_bytes, build_octree(g, config).bytes());
}

}  // namespace
}  // namespace rtcl::test
