// The SAH kd-tree (src/rtcl/accel/kdtree.cpp, kernels/accel/kdtree.cl):
// splits placed by the SAH over sorted events, perfect splits, leaves when
// no split pays, and traversal answers identical to brute force on soups
// with spheres, the bunny, a flat scene and rays in and on split planes,
// by the single-ray kernel and by the packet kernel
// (kernels/accel/kdtree_packet.cl: mixed direction signs and +0 / -0 in one
// packet, partial packets).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <memory>
#include <random>

#include "rtcl/accel/brute.hpp"
#include "rtcl/accel/structure_kernels.hpp"
#include "rtcl/accel/bsp.hpp"
#include "rtcl/accel/kdtree.hpp"
#include "rtcl/accel/kdtree_fused.hpp"
#include "rtcl/bounds/clip.hpp"
#include "rtcl/error.hpp"
#include "rtcl/render/ray_order.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/error_of.hpp"
#include "support/fixtures.hpp"
#include "support/kd_support.hpp"

namespace rtcl::test {
namespace {

TEST(KdClip, ClippedBoundsAreThoseOfThePartInsideTheBox) {
  glm::dvec3 lo, hi;
  // A triangle crossing x = 0.5: the part in x <= 0.5.
  ASSERT_TRUE(clip_triangle_bounds({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, -1, -1}, {0.5, 2, 2}, &lo, &hi));
  EXPECT_EQ(hi.x, 0.5);
  EXPECT_EQ(hi.y, 1.0);
  // The part in x >= 0.5 reaches only y <= 0.5 (perfect split).
  ASSERT_TRUE(clip_triangle_bounds({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.5, -1, -1}, {2, 2, 2}, &lo, &hi));
  EXPECT_EQ(lo.x, 0.5);
  EXPECT_DOUBLE_EQ(hi.y, 0.5);
  // Its box meets [0.6, 1] x [0.6, 1], the triangle does not.
  EXPECT_FALSE(clip_triangle_bounds({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.6, 0.6, -1}, {1, 1, 1}, &lo, &hi));
  // Touching in a vertex keeps the vertex.
  ASSERT_TRUE(clip_triangle_bounds({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, -1, -1}, {2, 1, 1}, &lo, &hi));
  EXPECT_EQ(lo.x, 1.0);
  EXPECT_EQ(hi.x, 1.0);
}

KdTreeConfig exact_below(std::size_t n) {
  KdTreeConfig c;
  c.exact_below = n;
  return c;
}

// Clipping to both children at once (the parent clip shared) gives what
// clipping to each child gives, to the rounding of double.
TEST(KdClip, SplitClipsAgreeWithClippingToEachChild) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 2.0);
  const glm::dvec3 lower(0.0), upper(1.0);
  for (int i = 0; i < 2000; ++i) {
    glm::dvec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng)), c(u(rng), u(rng), u(rng));
    int axis = i % 3;
    double p = 0.5 * (u(rng) + 1.0) / 1.5;
    ClipSplit split = clip_triangle_split(a, b, c, lower, upper, axis, p, p);
    glm::dvec3 below_upper = upper, above_lower = lower, lo, hi;
    below_upper[axis] = p;
    above_lower[axis] = p;
    bool below = clip_triangle_bounds(a, b, c, lower, below_upper, &lo, &hi);
    ASSERT_EQ(split.below, below) << i;
    for (int k = 0; below && k < 3; ++k) {
      EXPECT_NEAR(split.below_lower[k], lo[k], 1e-12) << i;
      EXPECT_NEAR(split.below_upper[k], hi[k], 1e-12) << i;
    }
    bool above = clip_triangle_bounds(a, b, c, above_lower, upper, &lo, &hi);
    ASSERT_EQ(split.above, above) << i;
    for (int k = 0; above && k < 3; ++k) {
      EXPECT_NEAR(split.above_lower[k], lo[k], 1e-12) << i;
      EXPECT_NEAR(split.above_upper[k], hi[k], 1e-12) << i;
    }
  }
}

TEST(KdBuild, SahCutsOffEmptySpaceAndStopsWhenNoSplitPays) {
  // Two clusters far apart: the first split separates them, whether the
  // root is split at bin boundaries or by the exact sweep.
  Geometry a = random_soup(200, 1, 0.02f, 0.1f);
  Geometry b = random_soup(200, 2, 0.02f, 0.1f, glm::vec3(0.9f));
  Geometry g = a;
  auto base = static_cast<std::uint32_t>(g.vertices.size());
  g.vertices.insert(g.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (glm::uvec3 t : b.triangles) g.triangles.push_back(t + base);
  g.source = "two clusters";
  for (std::size_t exact : {std::size_t{0}, std::size_t{1} << 30}) {
    KdTree t = build_kdtree(g, exact_below(exact));
    ASSERT_NE(t.nodes[0].flags & 3u, RTCL_KD_LEAF) << exact;
    float split = std::bit_cast<float>(t.nodes[0].data);
    EXPECT_GT(split, 0.1f) << exact;
    EXPECT_LT(split, 0.9f) << exact;
    EXPECT_LE(t.depth, static_cast<std::uint32_t>(kdtree_depth({}, 400))) << exact;
  }
  // One triangle: no split beats the leaf.
  Geometry one;
  one.source = "one triangle";
  one.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  one.triangles = {{0, 1, 2}};
  EXPECT_EQ(build_kdtree(one).nodes.size(), 1u);
  // Fewer straddling references than the BSP on the same soup.
  Geometry soup = random_soup(3000, 3);
  EXPECT_LT(build_kdtree(soup).references_per_primitive(), build_bsp(soup).references_per_primitive());
}

// A room whose walls span every plane: no split costs less than one leaf
// of all its triangles, but a node of more than 32 references still splits
// (up to two such splits on a path), and the tree traces as brute force.
TEST(KdBuild, ARoomOfWallsIsSplitThoughNoSplitBeatsItsLeaf) {
  Geometry g = load_mesh(scene_path("cornell_box/CornellBox-Original.obj")).geometry;
  validate(g);
  ASSERT_GT(g.triangles.size(), 32u);
  KdTree t = build_kdtree(g);
  EXPECT_NE(t.nodes[0].flags & 3u, RTCL_KD_LEAF);
  std::vector<Ray> rays = random_rays(g, 600, 31);
  std::vector<Ray> planes = split_plane_rays(t, 32, 600);
  rays.insert(rays.end(), planes.begin(), planes.end());
  expect_same_as_brute(*make_kdtree(test_device(), g), g, rays, Precision::robust);
}

// The build's threads change nothing in the tree: the binned levels hand
// whole subtrees to workers, and the exact build's subtrees do not depend
// on which thread builds them.
TEST(KdBuild, TheTreeDoesNotDependOnTheThreads) {
  Geometry g = random_soup(20000, 13);
  for (std::size_t exact : {std::size_t{0}, std::size_t{64}, std::size_t{1} << 30}) {
    KdTreeConfig one = exact_below(exact), two = exact_below(exact);
    one.thread_count = 1;
    two.thread_count = 2;
    KdTree a = build_kdtree(g, one), b = build_kdtree(g, two);
    ASSERT_EQ(a.nodes.size(), b.nodes.size()) << exact;
    EXPECT_EQ(std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(KdNode)), 0) << exact;
    EXPECT_EQ(a.refs, b.refs) << exact;
    ASSERT_EQ(a.fused.size(), b.fused.size()) << exact;
    EXPECT_EQ(std::memcmp(a.fused.data(), b.fused.data(), a.fused.size() * sizeof(Bvh8Node)), 0) << exact;
  }
}

// The builder's leaf boxes (the union of the bounds it clipped while
// splitting) hold the boxes a fresh clip of each leaf's primitives to its
// cell gives (what flatten_kd_tree computes for builders that do not keep
// them, as the BSP), and almost all are the same box: the two differ only
// where a later plane, which did not cut the clipped part, re-rounds it.
TEST(KdBuild, LeafBoxesAreThoseOfTheTrianglesClippedToTheirCells) {
  Geometry g = load_mesh(scene_path("stanford_bunny/bunny.obj")).geometry;
  validate(g);
  KdPrimitives prims = kd_primitives(g, "kdtree", 0);
  for (std::size_t exact : {std::size_t{0}, std::size_t{1} << 30}) {
    KdTree t = build_kdtree(g, exact_below(exact));
    std::vector<Bvh8Node> clipped = fuse_kd_nodes(t.nodes, t.header, [&](std::size_t leaf, const KdBox& cell) {
      KdBox box = KdBox::empty();
      glm::dvec3 lo(cell.lower[0], cell.lower[1], cell.lower[2]), hi(cell.upper[0], cell.upper[1], cell.upper[2]);
      const std::uint32_t first = t.nodes[leaf].flags >> 2;
      for (std::uint32_t k = first; k < first + t.nodes[leaf].data; ++k) {
        glm::dvec3 cl, cu;
        if (!prims.clip(static_cast<std::uint32_t>(t.refs[k]), lo, hi, &cl, &cu)) continue;
        for (int a = 0; a < 3; ++a) {
          box.lower[a] = std::min(box.lower[a], kd_round_float(cl[a], true));
          box.upper[a] = std::max(box.upper[a], kd_round_float(cu[a], false));
        }
      }
      return box;
    });
    ASSERT_EQ(clipped.size(), t.fused.size()) << exact;
    std::size_t lanes = 0, same = 0;
    for (std::size_t i = 0; i < clipped.size(); ++i)
      for (int k = 0; k < 8; ++k) {
        if (t.fused[i].child[k] == RTCL_KD_NO_CELL) continue;
        ++lanes;
        bool equal = true;
        for (int a = 0; a < 3; ++a) {
          EXPECT_LE(t.fused[i].bounds[a][k], clipped[i].bounds[a][k]) << exact << " node " << i << " lane " << k;
          EXPECT_GE(t.fused[i].bounds[3 + a][k], clipped[i].bounds[3 + a][k]) << exact << " node " << i;
          equal = equal && t.fused[i].bounds[a][k] == clipped[i].bounds[a][k] &&
                  t.fused[i].bounds[3 + a][k] == clipped[i].bounds[3 + a][k];
        }
        same += equal;
      }
    EXPECT_GE(static_cast<double>(same), 0.99 * static_cast<double>(lanes)) << exact;
  }
}

// The options' ranges are declared once (kdtree_structure()) and checked
// by make_accel; the builder itself refuses only a tree the device cannot
// hold.
TEST(KdBuild, BadOptionsAreErrorsNamingTheOption) {
  Geometry g = random_soup(10, 1);
  KdTreeConfig tiny;
  tiny.max_alloc_bytes = 64;
  EXPECT_NE(error_of([&] { build_kdtree(g, tiny); }).find("CL_DEVICE_MAX_MEM_ALLOC_SIZE"), std::string::npos);
  const std::pair<const char*, const char*> bad[] = {{"kdtree:depth=65", "depth must be in [0, 64]"},
                                                     {"kdtree:ct=0", "ct must be > 0"},
                                                     {"kdtree:ci=-2", "ci must be > 0"},
                                                     {"kdtree:empty=1", "empty must be in [0, 0.99]"},
                                                     {"kdtree-packet:batch=9", "batch must be in [1, 8]"}};
  for (const auto& [spec, problem] : bad) {
    std::string e = error_of([&] { make_accel(test_device(), spec, g); });
    EXPECT_EQ(e.rfind("make_accel name \"" + std::string(spec) + "\": " + problem, 0), 0u) << e;
  }
}

// A soup and a 3x3x3 lattice of spheres of growing radii through it.
Geometry soup_and_spheres(std::size_t triangles, std::uint32_t seed) {
  Geometry g = random_soup(triangles, seed);
  for (int k = 0; k < 27; ++k)
    g.spheres.push_back({glm::vec3(0.2f + 0.3f * (k % 3), 0.2f + 0.3f * (k / 3 % 3), 0.2f + 0.3f * (k / 9)),
                         0.01f + 0.004f * static_cast<float>(k)});
  g.source = "soup and spheres";
  return g;
}

TEST(KdTrace, MatchesBruteForceOnSoupsAndSplitPlaneRays) {
  Geometry g = soup_and_spheres(600, 5);
  // The default costs (leaves of up to a few runs of 8) and the classic SAH
  // (a cost per primitive: a deeper tree of small leaves, more planes),
  // each split only by binning and only by the exact sweep.
  KdTreeConfig classic;
  classic.batch = 1;
  classic.traversal_cost = 30.0;
  std::vector<KdTreeConfig> configs;
  for (KdTreeConfig c : {KdTreeConfig{}, classic})
    for (std::size_t exact : {std::size_t{0}, std::size_t{1} << 30}) {
      c.exact_below = exact;
      configs.push_back(c);
    }
  for (const KdTreeConfig& config : configs) {
    KdTree t = build_kdtree(g, config);
    std::vector<Ray> rays = random_rays(g, 600, 6);
    std::vector<Ray> planes = split_plane_rays(t, 7, 1200);
    rays.insert(rays.end(), planes.begin(), planes.end());
    for (Precision level : test_precisions())
      expect_same_as_brute(*make_kdtree(test_device(), g, config, AccelConfig{level, {}}), g, rays, level);
  }
}

TEST(KdTrace, MatchesBruteForceOnTheBunny) {
  Geometry g = load_mesh(scene_path("stanford_bunny/bunny.obj")).geometry;
  validate(g);
  std::vector<Ray> rays = random_rays(g, 800, 41);
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  Aabb box = g.bounds();
  for (int i = 0; i < 400; ++i) {  // origins inside leaves
    glm::vec3 o = box.lower + box.extent() * glm::vec3(unit(rng), unit(rng), unit(rng));
    rays.push_back({o.x, o.y, o.z, normal(rng), normal(rng), normal(rng), 0.0f, INFINITY});
  }
  std::vector<Ray> planes = split_plane_rays(build_kdtree(g), 43, 800);
  rays.insert(rays.end(), planes.begin(), planes.end());
  expect_same_as_brute(*make_kdtree(test_device(), g), g, rays, Precision::robust, false);
}

// An n x n grid of cells over the unit square in the plane z = 0.25, two
// triangles each, sharing edges and vertices.
Geometry flat_grid(int n) {
  Geometry g;
  g.source = "flat grid";
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) g.vertices.push_back({i / float(n), j / float(n), 0.25f});
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      std::uint32_t v = j * (n + 1) + i;
      g.triangles.push_back({v, v + 1, v + n + 2});
      g.triangles.push_back({v, v + n + 2, v + n + 1});
    }
  return g;
}

// A scene flat along z (every split on z would be useless), a grid of
// triangles with shared edges on the split planes.
TEST(KdTrace, FlatSceneAndSharedEdgesOnSplitPlanes) {
  const int n = 16;
  Geometry g = flat_grid(n);
  KdTree t = build_kdtree(g);
  std::vector<Ray> rays = split_plane_rays(t, 8, 900);
  std::mt19937 rng(9);
  std::uniform_int_distribution<int> k(0, n);
  for (int i = 0; i < 300; ++i) {  // straight down through grid vertices and edges
    float x = k(rng) / float(n), y = (k(rng) + 0.5f * (i % 2)) / float(n);
    rays.push_back({x, y, 1.0f, (i % 3) ? 0.0f : -0.0f, 0.0f, -1.0f, 0.0f, INFINITY});
  }
  for (Precision level : test_precisions()) {
    expect_same_as_brute(*make_kdtree(test_device(), g, {}, AccelConfig{level, {}}), g, rays, level);
    expect_same_as_brute(*make_bsp(test_device(), g, {}, AccelConfig{level, {}}), g, rays, level);
  }
}

TEST(KdTrace, ReportsStats) {
  Geometry g = random_soup(1000, 4);
  auto kd = make_kdtree(test_device(), g);
  EXPECT_EQ(kd->name(), "kdtree");
  KdTree host = build_kdtree(g);
  EXPECT_EQ(kd->stats().device_bytes, host.bytes());
  EXPECT_EQ(kd->stats().leaf_count, host.leaf_count);
  EXPECT_EQ(kd->stats().primitive_count, 1000u);
  EXPECT_EQ(make_accel(test_device(), "kdtree:depth=20,ct=10,ci=30,empty=0.5", g)->name(), "kdtree");
  EXPECT_EQ(make_accel(test_device(), "bsp:depth=12,leaf=3", g)->name(), "bsp");
}

// The packet kernel (kernels/accel/kdtree_packet.cl) on the same tree:
// "kdtree-packet" traces every call in packets of 8 rays.
std::unique_ptr<Accel> kd_packets(const Geometry& g, const KdTreeConfig& config = {},
                                  Precision level = Precision::robust) {
  return make_kdtree(test_device(), g, config, AccelConfig{level, {}}, "kdtree-packet", KdTraversal::packet);
}

// Rays from one eye through a width x height grid over the geometry's box
// (pixel order): coherent packets.
std::vector<Ray> eye_rays(const Geometry& g, std::uint32_t width, std::uint32_t height) {
  Aabb box = g.bounds();
  glm::vec3 c = box.center(), e = box.extent();
  float size = std::max(e.x, e.y);
  glm::vec3 eye = c + glm::vec3(0.15f * e.x, 0.1f * e.y, 2.0f * size);
  std::vector<Ray> rays;
  for (std::uint32_t y = 0; y < height; ++y)
    for (std::uint32_t x = 0; x < width; ++x) {
      glm::vec3 target = c + size * glm::vec3((x + 0.5f) / width - 0.5f, 0.5f - (y + 0.5f) / height, 0.0f);
      glm::vec3 d = glm::normalize(target - eye);
      rays.push_back({eye.x, eye.y, eye.z, d.x, d.y, d.z, 0.0f, INFINITY});
    }
  return rays;
}

TEST(KdPacket, IsRegisteredAndTracesEveryCallInPackets) {
  Geometry g = random_soup(300, 21);
  auto packets = make_accel(test_device(), "kdtree-packet:ct=10,depth=20", g);
  EXPECT_EQ(packets->name(), "kdtree-packet");
  EXPECT_EQ(packets->rays_per_work_item(Coherence::incoherent), 8u);
  auto kd = make_accel(test_device(), "kdtree:ct=10,depth=20", g);
  EXPECT_EQ(kd->rays_per_work_item(Coherence::incoherent), 1u);
  EXPECT_EQ(kd->rays_per_work_item(Coherence::coherent), packets_for_coherent_calls(test_device().info()) ? 8u : 1u);
  EXPECT_EQ(make_accel(test_device(), "bsp", g)->rays_per_work_item(Coherence::coherent), 1u);
  EXPECT_EQ(packets->stats().node_count, kd->stats().node_count);  // the same tree
}

// Random rays (every lane of a packet in its own octant: mixed direction
// signs on every split axis) and split-plane rays (in planes, on planes,
// axis-parallel with +0 / -0), a count that leaves a partial packet.
TEST(KdPacket, MatchesBruteForceOnSoupsAndSplitPlaneRays) {
  Geometry g = soup_and_spheres(600, 25);
  KdTreeConfig classic;
  classic.batch = 1;
  classic.traversal_cost = 30.0;
  for (const KdTreeConfig& config : {KdTreeConfig{}, classic}) {
    KdTree t = build_kdtree(g, config);
    std::vector<Ray> rays = random_rays(g, 603, 26);
    std::vector<Ray> planes = split_plane_rays(t, 27, 1203);
    rays.insert(rays.end(), planes.begin(), planes.end());
    for (Precision level : test_precisions()) expect_same_as_brute(*kd_packets(g, config, level), g, rays, level);
  }
}

TEST(KdPacket, MatchesBruteForceOnTheBunny) {
  Geometry g = load_mesh(scene_path("stanford_bunny/bunny.obj")).geometry;
  validate(g);
  std::vector<Ray> rays = gather<Ray>(eye_rays(g, 96, 96), tile_order(96, 96));  // coherent packets
  std::vector<Ray> random = random_rays(g, 805, 44);
  rays.insert(rays.end(), random.begin(), random.end());
  std::vector<Ray> planes = split_plane_rays(build_kdtree(g), 45, 803);
  rays.insert(rays.end(), planes.begin(), planes.end());
  expect_same_as_brute(*kd_packets(g), g, rays, Precision::robust, false);
  expect_same_as_brute(*kd_packets(g, {}, Precision::exact), g, rays, Precision::exact, false);
}

// Coherent calls on "kdtree" take the packet kernel and answer as its
// single-ray calls do: the same t bit for bit, the same occlusion.
TEST(KdPacket, CoherentCallsMatchIncoherentOnes) {
  Geometry g = soup_and_spheres(2000, 31);
  auto kd = make_accel(test_device(), "kdtree", g);
  std::vector<Ray> rays = gather<Ray>(eye_rays(g, 64, 64), tile_order(64, 64));
  std::vector<Ray> random = random_rays(g, 301, 32);
  rays.insert(rays.end(), random.begin(), random.end());
  for (Query q : {Query::closest, Query::any}) {
    auto single = run_query(*kd, rays, q);
    auto packed = run_query(*kd, rays, q, Coherence::coherent);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < rays.size(); ++i)
      if ((single[i].prim < 0) != (packed[i].prim < 0) ||
          (q == Query::closest && std::memcmp(&single[i].t, &packed[i].t, sizeof(float)) != 0))
        ++differ;
    EXPECT_EQ(differ, 0u) << (q == Query::closest ? "closest" : "any") << " of " << rays.size();
  }
}

// A flat scene crossed straight down with +0 / -0 components side by side
// in one packet, through shared edges and vertices on split planes.
TEST(KdPacket, FlatSceneWithSignedZerosInOnePacket) {
  const int n = 16;
  Geometry g = flat_grid(n);
  std::vector<Ray> rays = split_plane_rays(build_kdtree(g), 28, 901);
  std::mt19937 rng(29);
  std::uniform_int_distribution<int> k(0, n);
  for (int i = 0; i < 301; ++i) {
    float x = k(rng) / float(n), y = (k(rng) + 0.5f * (i % 2)) / float(n);
    float zero = (i % 3) ? 0.0f : -0.0f;
    rays.push_back({x, y, (i % 5) ? 1.0f : -1.0f, zero, (i % 4) ? -0.0f : 0.0f, (i % 5) ? -1.0f : 1.0f, 0.0f,
                    INFINITY});
  }
  for (Precision level : test_precisions()) expect_same_as_brute(*kd_packets(g, {}, level), g, rays, level);
}

// Ray counts 1 .. 17 leave partial packets; invalid rays share packets with
// valid ones; the hits past ray_count stay untouched.
TEST(KdPacket, PartialPacketsAndInvalidRays) {
  Geometry g = random_soup(400, 33);
  auto packets = kd_packets(g);
  auto brute = make_brute(test_device(), g, AccelConfig{Precision::robust, {}});
  std::vector<Ray> rays = random_rays(g, 24, 34);
  rays[1].dx = std::numeric_limits<float>::quiet_NaN();
  rays[3].dx = rays[3].dy = rays[3].dz = 0.0f;
  rays[4].tmin = 2.0f;
  rays[4].tmax = 1.0f;
  const Device& device = test_device();
  for (std::size_t count = 1; count <= 17; ++count) {
    SCOPED_TRACE("ray_count " + std::to_string(count));
    cl::Buffer ray_buffer = device.upload(rays.data(), rays.size() * sizeof(Ray), "test rays");
    std::vector<Hit> hits(rays.size(), Hit{-7.0f, -7.0f, -7.0f, -7});
    cl::Buffer hit_buffer = device.upload(hits.data(), hits.size() * sizeof(Hit), "test hits");
    packets->trace(Query::closest, ray_buffer, hit_buffer, count).wait();
    device.queue().enqueueReadBuffer(hit_buffer, CL_TRUE, 0, hits.size() * sizeof(Hit), hits.data());
    auto expected = run_query(*brute, std::vector<Ray>(rays.begin(), rays.begin() + static_cast<long>(count)),
                              Query::closest);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      if (i < count) {
        EXPECT_EQ(hits[i].prim >= 0, expected[i].prim >= 0) << "ray " << i;
        if (expected[i].prim >= 0) EXPECT_EQ(hits[i].t, expected[i].t) << "ray " << i;
      } else {
        EXPECT_EQ(hits[i].prim, -7) << "hit " << i << " written past ray_count";
      }
    }
  }
}

}  // namespace
}  // namespace rtcl::test
