#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <unordered_map>

#include "rtcl/accel/bvh.hpp"
#include "rtcl/accel/refit.hpp"
#include "rtcl/accel/structure_kernels.hpp"
#include "rtcl/error.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/fixtures.hpp"
#include "support/reference.hpp"

namespace rtcl::test {
namespace {


const char* builder_name(BvhBuilder b) { return b == BvhBuilder::sah ? "sah" : "ploc"; }

BvhConfig config_for(BvhBuilder b) {
  BvhConfig config;
  config.builder = b;
  return config;
}

const char* accel_for(BvhBuilder b) { return b == BvhBuilder::sah ? "bvh" : "bvh-ploc"; }

// The builder inputs build_binary_bvh derives: stored primitives with their
// boxes (spheres widened as the BVH widens them, so compare loosely).
struct BuildInputs {
  std::vector<Aabb> bounds;
  std::vector<std::uint32_t> ids;
};
BuildInputs triangle_inputs(const Geometry& g) {
  BuildInputs in;
  for (std::uint32_t p : stored_primitives(g))
    if (p < g.triangles.size()) {
      in.bounds.push_back(g.primitive_bounds(p));
      in.ids.push_back(p);
    }
  return in;
}

BuildTree build_with(BvhBuilder b, const BuildInputs& in) {
  return b == BvhBuilder::sah ? build_sah(in.bounds, in.ids) : build_ploc(in.bounds, in.ids);
}

bool box_contains(const float bounds[6][RTCL_BLOCK_WIDTH], int lane, const Aabb& box) {
  for (int a = 0; a < 3; ++a)
    if (!(bounds[a][lane] <= box.lower[a] && bounds[3 + a][lane] >= box.upper[a])) return false;
  return true;
}

// Independent walk of the device layout: every stored primitive in exactly
// one block lane, every child box containing all primitives below it, and
// the stack bound recomputed as the kernel uses the stack (a node pushes its
// children, then one is popped): max over nodes of children + the sum of
// (children - 1) over the ancestors. "" when all hold.
std::string check_wide(const Bvh8& bvh, const Geometry& g) {
  std::vector<int> seen(g.primitive_count(), 0);
  std::uint32_t stack_need = 0;
  std::vector<int> node_seen(bvh.nodes.size(), 0);
  std::string problem;
  // Returns the union of the primitive boxes below child reference `ref`.
  std::function<Aabb(rtcl_i32, std::uint32_t)> walk = [&](rtcl_i32 ref, std::uint32_t stack) -> Aabb {
    Aabb below;
    if (ref >= 0) {
      if (static_cast<std::size_t>(ref) >= bvh.nodes.size() || node_seen[ref]++) {
        problem = "node " + std::to_string(ref) + " missing or reached twice";
        return below;
      }
      const Bvh8Node& node = bvh.nodes[ref];
      std::uint32_t children = 0;
      for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) children += node.child[lane] != RTCL_CHILD_EMPTY;
      if (children == 0) problem = "node " + std::to_string(ref) + " has no child";
      stack_need = std::max(stack_need, stack + children);  // pushed, before one is popped
      std::uint32_t need = stack + children - 1;
      for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
        if (node.child[lane] == RTCL_CHILD_EMPTY) {
          if (!(node.bounds[0][lane] == kInf && node.bounds[3][lane] == -kInf))
            problem = "empty slot with a box in node " + std::to_string(ref);
          continue;
        }
        Aabb child = walk(node.child[lane], need);
        if (!box_contains(node.bounds, lane, child))
          problem = "node " + std::to_string(ref) + " lane " + std::to_string(lane) + " misses a primitive";
        below.grow(child);
      }
      return below;
    }
    int leaf = ~ref;
    bool spheres = leaf & 1;
    std::size_t block = static_cast<std::size_t>(leaf >> 1);
    if (block >= (spheres ? bvh.blocks.spheres.size() : bvh.blocks.triangles.size())) {
      problem = "leaf reference to a missing block";
      return below;
    }
    const rtcl_i32* prims = spheres ? bvh.blocks.spheres[block].prim : bvh.blocks.triangles[block].prim;
    int used = 0;
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
      if (prims[lane] < 0) continue;
      ++used;
      ++seen[static_cast<std::size_t>(prims[lane])];
      below.grow(g.primitive_bounds(static_cast<std::size_t>(prims[lane])));
    }
    if (used == 0) problem = "empty block";
    return below;
  };
  walk(0, 0);
  if (!problem.empty()) return problem;
  for (std::size_t p = 0; p < seen.size(); ++p) {
    int expected = p >= g.triangles.size() || !zero_area(g, p) ? 1 : 0;
    if (seen[p] != expected)
      return "primitive " + std::to_string(p) + " stored " + std::to_string(seen[p]) + " times";
  }
  for (std::size_t n = 0; n < node_seen.size(); ++n)
    if (!node_seen[n]) return "node " + std::to_string(n) + " unreachable";
  if (stack_need != bvh.stack_size)
    return "stack bound " + std::to_string(bvh.stack_size) + ", recomputed " + std::to_string(stack_need);
  return "";
}

void expect_matches_reference(const Accel& accel, const Geometry& g, const std::vector<Ray>& rays) {
  for (Query q : {Query::closest, Query::any}) {
    auto hits = run_query(accel, rays, q);
    std::size_t failures = 0;
    auto report = judge_all(g, rays, hits, q, &failures);
    EXPECT_EQ(failures, 0u) << accel.name() << (q == Query::closest ? " closest: " : " any: ")
                            << (report.empty() ? "" : report[0]);
  }
}

// Soup of triangles with spheres mixed in, both kinds interleaved in space.
Geometry soup_with_spheres(std::size_t triangles, std::size_t spheres, std::uint32_t seed) {
  Geometry g = random_soup(triangles, seed);
  std::mt19937 rng(seed + 1);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (std::size_t i = 0; i < spheres; ++i)
    g.spheres.push_back({{unit(rng), unit(rng), unit(rng)}, 0.005f + 0.03f * unit(rng)});
  return g;
}

// `count` triangles all centred on one point, each a scaled copy of one
// shape: every centroid coincides, boxes are nested.
Geometry nested_triangles(std::size_t count) {
  Geometry g;
  g.source = "nested triangles";
  for (std::size_t i = 0; i < count; ++i) {
    float s = 0.01f * static_cast<float>(i + 1);
    auto base = static_cast<std::uint32_t>(g.vertices.size());
    g.vertices.push_back(glm::vec3(-s, -s, 0.1f * s));
    g.vertices.push_back(glm::vec3(2.0f * s, -s, -0.2f * s));
    g.vertices.push_back(glm::vec3(-s, 2.0f * s, 0.1f * s));
    g.triangles.push_back({base, base + 1, base + 2});
  }
  return g;
}

Geometry identical_triangles(std::size_t count) {
  Geometry g;
  g.source = "identical triangles";
  g.vertices = {{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.5f}};
  g.triangles.assign(count, glm::uvec3(0, 1, 2));
  return g;
}

Geometry load(const std::string& relative) {
  Geometry g = load_mesh(scene_path(relative)).geometry;
  validate(g);
  return g;
}

class BvhBuilders : public ::testing::TestWithParam<BvhBuilder> {};

INSTANTIATE_TEST_SUITE_P(Bvh, BvhBuilders, ::testing::Values(BvhBuilder::sah, BvhBuilder::ploc),
                         [](const auto& info) { return std::string(builder_name(info.param)); });

TEST_P(BvhBuilders, TreeHoldsEveryPrimitiveOnceInSmallLeaves) {
  Geometry g = random_soup(5000, 11);
  BuildInputs in = triangle_inputs(g);
  BuildTree tree = build_with(GetParam(), in);
  EXPECT_EQ(check(tree, in.bounds, in.ids, 8), "");
  EXPECT_EQ(tree.prims.size(), in.ids.size());
  // A corrupted tree is caught: the check can fail.
  BuildTree broken = tree;
  for (BuildNode& n : broken.nodes)
    if (n.is_leaf()) {
      n.bounds.upper.x = n.bounds.lower.x - 1.0f;
      break;
    }
  EXPECT_NE(check(broken, in.bounds, in.ids, 8), "");
}

TEST_P(BvhBuilders, WideLayoutIsConsistentWithSpheresMixedIn) {
  Geometry g = soup_with_spheres(3000, 300, 5);
  Bvh8 bvh = flatten_bvh8(build_binary_bvh(g, config_for(GetParam())), g);
  EXPECT_EQ(check_wide(bvh, g), "");
  EXPECT_GT(bvh.stack_size, 0u);
  EXPECT_GE(bvh_kernel_stack_size(bvh.stack_size), bvh.stack_size);
  EXPECT_EQ(bvh_kernel_stack_size(bvh.stack_size) % 8, 0u);
  // No leaf mixes the kinds: blocks hold only their own kind.
  for (const TriangleBlock& b : bvh.blocks.triangles)
    for (rtcl_i32 p : b.prim) EXPECT_LT(p, static_cast<rtcl_i32>(g.triangles.size()));
  for (const SphereBlock& b : bvh.blocks.spheres)
    for (rtcl_i32 p : b.prim) EXPECT_TRUE(p < 0 || p >= static_cast<rtcl_i32>(g.triangles.size()));
}

TEST_P(BvhBuilders, DegenerateInputsGiveValidShallowTrees) {
  struct Case {
    const char* what;
    Geometry g;
    std::uint32_t max_depth;  // binary levels
  };
  std::vector<Case> cases;
  cases.push_back({"one triangle", random_soup(1, 3), 1});
  cases.push_back({"nine triangles", random_soup(9, 4), 8});
  cases.push_back({"coincident centroids", nested_triangles(3000), 64 + 12});
  cases.push_back({"identical triangles", identical_triangles(100000), 20});
  for (Case& c : cases) {
    SCOPED_TRACE(c.what);
    BuildInputs in = triangle_inputs(c.g);
    BuildTree tree = build_with(GetParam(), in);
    EXPECT_EQ(check(tree, in.bounds, in.ids, 8), "");
    EXPECT_LE(tree.depth(), c.max_depth);
    Bvh8 bvh = flatten_bvh8(tree, c.g);
    EXPECT_EQ(check_wide(bvh, c.g), "");
  }
}

TEST_P(BvhBuilders, ZeroAreaTrianglesAreNotStored) {
  Geometry g = random_soup(500, 8);
  std::size_t n = g.triangles.size();
  for (std::size_t i = 0; i < n; i += 5) g.triangles[i].z = g.triangles[i].y;  // two equal corners
  g.vertices.push_back({0.5f, 0.5f, 0.5f});
  g.triangles.push_back({static_cast<std::uint32_t>(g.vertices.size() - 1), static_cast<std::uint32_t>(g.vertices.size() - 1),
                         static_cast<std::uint32_t>(g.vertices.size() - 1)});
  BuildTree tree = build_binary_bvh(g, config_for(GetParam()));
  EXPECT_EQ(tree.prims.size(), stored_primitives(g).size());
  EXPECT_EQ(tree.prims.size(), n - n / 5);
  Bvh8 bvh = flatten_bvh8(tree, g);
  EXPECT_EQ(check_wide(bvh, g), "");
  auto accel = make_bvh(test_device(), g, config_for(GetParam()));
  EXPECT_EQ(accel->stats().zero_area_skipped, n / 5 + 1);
  EXPECT_EQ(accel->stats().primitive_count, n - n / 5);
  expect_matches_reference(*accel, g, random_rays(g, 500, 9));
}

TEST_P(BvhBuilders, MatchesReferenceOnSoupWithSpheres) {
  Geometry g = soup_with_spheres(2000, 200, 21);
  auto accel = make_accel(test_device(), accel_for(GetParam()), g);
  EXPECT_EQ(accel->name(), accel_for(GetParam()));
  expect_matches_reference(*accel, g, random_rays(g, 2000, 22));
}

TEST_P(BvhBuilders, MatchesReferenceOnSpheresOnly) {
  Geometry g;
  g.source = "spheres";
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int i = 0; i < 300; ++i) g.spheres.push_back({{unit(rng), unit(rng), unit(rng)}, 0.01f + 0.05f * unit(rng)});
  auto accel = make_accel(test_device(), accel_for(GetParam()), g);
  expect_matches_reference(*accel, g, random_rays(g, 1000, 4));
}

TEST_P(BvhBuilders, MatchesReferenceOnDegenerateInputs) {
  std::vector<Geometry> scenes = {random_soup(1, 31), random_soup(9, 32), nested_triangles(2000),
                                  identical_triangles(5000)};
  for (const Geometry& g : scenes) {
    SCOPED_TRACE(g.source + " of " + std::to_string(g.triangles.size()));
    auto accel = make_accel(test_device(), accel_for(GetParam()), g);
    expect_matches_reference(*accel, g, random_rays(g, 300, 33));
  }
}

// Rays along the common axis of nested boxes enter every child: the deepest
// stack the tree allows is used, and must not overflow.
TEST_P(BvhBuilders, DeepTreesUseTheirWholeStackSafely) {
  Geometry g = nested_triangles(3000);
  Bvh8 bvh = flatten_bvh8(build_binary_bvh(g, config_for(GetParam())), g);
  EXPECT_GE(bvh.stack_size, 16u);
  auto accel = make_accel(test_device(), accel_for(GetParam()), g);
  std::vector<Ray> rays;
  for (int i = 0; i < 64; ++i) {
    float e = 1e-3f * static_cast<float>(i);
    rays.push_back({e, e, 10.0f, 0.0f, 0.0f, -1.0f, 0.0f, kInf});
    rays.push_back({e, -e, -10.0f, 0.0f, 0.0f, 1.0f, 0.0f, kInf});
  }
  expect_matches_reference(*accel, g, rays);
}

// Both structures on real meshes, rays from outside (random_rays) and from
// random points inside the bounds in random directions (interior views).
// The double-precision reference is O(triangles) per ray: computed once per
// ray and shared by the four answers judged.
void expect_real_mesh_matches(const char* file) {
  Geometry g = load(file);
  std::vector<Ray> rays = random_rays(g, 500, 41);
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  Aabb box = g.bounds();
  for (int i = 0; i < 500; ++i) {
    glm::vec3 o = box.lower + box.extent() * glm::vec3(unit(rng), unit(rng), unit(rng));
    rays.push_back({o.x, o.y, o.z, normal(rng), normal(rng), normal(rng), 0.0f, kInf});
  }
  std::vector<Hit> references = reference_closest_all(g, rays);
  for (const char* name : {"bvh", "bvh-ploc"}) {
    auto accel = make_accel(test_device(), name, g);
    for (Query q : {Query::closest, Query::any}) {
      auto hits = run_query(*accel, rays, q);
      std::size_t failures = 0;
      auto report = judge_all(g, rays, hits, q, references, &failures);
      EXPECT_EQ(failures, 0u) << name << (q == Query::closest ? " closest: " : " any: ")
                              << (report.empty() ? "" : report[0]);
    }
  }
}

// The tree in a canonical form: depth first, each node's box, then a leaf's
// primitive ids or an inner node's children; node numbering left out.
void canonical(const BuildTree& tree, std::uint32_t n, std::vector<double>& out) {
  const BuildNode& node = tree.nodes[n];
  for (int a = 0; a < 3; ++a) {
    out.push_back(node.bounds.lower[a]);
    out.push_back(node.bounds.upper[a]);
  }
  out.push_back(node.count);
  if (node.is_leaf()) {
    for (std::uint32_t k = node.first; k < node.first + node.count; ++k) out.push_back(tree.prims[k]);
    return;
  }
  for (std::uint32_t c : node.child) canonical(tree, c, out);
}

// The subtrees built on other threads and the ranges binned by two threads
// (at 16384 references and more) give the tree of the one-thread build.
TEST(Bvh, SahTreeDoesNotDependOnTheThreads) {
  Geometry g = random_soup(60000, 5);
  BuildInputs in = triangle_inputs(g);
  std::vector<double> one, many;
  canonical(build_sah(in.bounds, in.ids, {.thread_count = 1}), 0, one);
  for (unsigned threads : {2u, 4u}) {
    BuildTree tree = build_sah(in.bounds, in.ids, {.thread_count = threads});
    EXPECT_EQ(check(tree, in.bounds, in.ids, 8), "") << threads << " threads";
    many.clear();
    canonical(tree, 0, many);
    EXPECT_TRUE(one == many) << threads << " threads";
  }
}

// Every node's box is the union of its children's (inner) or of its
// primitives' boxes (leaf), exactly: "" when so, else the first node that
// is not.
std::string check_tight(const BuildTree& tree, const BuildInputs& in) {
  std::unordered_map<std::uint32_t, std::size_t> position;
  for (std::size_t i = 0; i < in.ids.size(); ++i) position[in.ids[i]] = i;
  for (std::size_t n = 0; n < tree.nodes.size(); ++n) {
    const BuildNode& node = tree.nodes[n];
    Aabb below;
    if (node.is_leaf())
      for (std::uint32_t k = node.first; k < node.first + node.count; ++k)
        below.grow(in.bounds[position.at(tree.prims[k])]);
    else
      for (std::uint32_t c : node.child) below.grow(tree.nodes[c].bounds);
    if (below.lower != node.bounds.lower || below.upper != node.bounds.upper) return "node " + std::to_string(n);
  }
  return "";
}

// Nodes of at least twice binning_samples references choose their plane
// from every k-th reference and take both sides' boxes from the partition:
// every box is still exact, the tree does not depend on the threads, it
// traces as the reference, and its SAH cost stays within 1% of binning
// every reference (30,000 triangles, sampled from nodes of 2048
// references down).
TEST(Bvh, SampledBinningKeepsExactBoxesAndTheCost) {
  Geometry g = random_soup(30000, 11);
  BuildInputs in = triangle_inputs(g);
  std::vector<double> one, many;
  const BuildTree tree = build_sah(in.bounds, in.ids, {.binning_samples = 1024, .thread_count = 1});
  EXPECT_EQ(check(tree, in.bounds, in.ids, 8), "");
  EXPECT_EQ(check_tight(tree, in), "");
  canonical(tree, 0, one);
  for (unsigned threads : {2u, 4u}) {
    many.clear();
    canonical(build_sah(in.bounds, in.ids, {.binning_samples = 1024, .thread_count = threads}), 0, many);
    EXPECT_TRUE(one == many) << threads << " threads";
  }
  std::vector<double> all;
  canonical(build_sah(in.bounds, in.ids, {.binning_samples = 0}), 0, all);
  EXPECT_FALSE(one == all) << "sampling changed no plane: the test does not reach it";

  BvhConfig sampled, every;
  sampled.sah.binning_samples = 1024;
  every.sah.binning_samples = 0;
  const double sampled_cost = bvh8_cost(flatten_bvh8(build_binary_bvh(g, sampled), g).nodes);
  const double every_cost = bvh8_cost(flatten_bvh8(build_binary_bvh(g, every), g).nodes);
  EXPECT_LT(sampled_cost, 1.01 * every_cost);
  auto accel = make_bvh(test_device(), g, sampled);
  expect_matches_reference(*accel, g, random_rays(g, 500, 29));
}

// The boxes pass splits the triangles into parts (16384 and more each) and
// moves each part's kept triangles down past the zero-area ones before it:
// the same tree as one part, every other triangle stored once.
TEST(Bvh, ZeroAreaTrianglesInEveryPartAreSkipped) {
  Geometry g = soup_with_spheres(40000, 500, 9);
  for (std::size_t i = 0; i < g.triangles.size(); i += 7) g.triangles[i].z = g.triangles[i].y;
  BvhConfig one, two;
  one.sah.thread_count = 1;
  two.sah.thread_count = 2;
  std::vector<double> a, b;
  canonical(build_binary_bvh(g, one), 0, a);
  BuildTree tree = build_binary_bvh(g, two);
  canonical(tree, 0, b);
  EXPECT_TRUE(a == b);
  EXPECT_EQ(check_wide(flatten_bvh8(tree, g), g), "");
}

// A caller's builder replaces the SAH for each kind of primitive (200
// spheres, 2000 triangles here); its tree is traced like the SAH's, and one
// missing a primitive is refused.
TEST(Bvh, CustomBuilderTreesAreTracedAndChecked) {
  Geometry g = soup_with_spheres(2000, 200, 21);
  std::vector<std::size_t> calls;
  BvhConfig config;
  config.custom_builder = [&calls](std::span<const Aabb> bounds, std::span<const std::uint32_t> ids) {
    calls.push_back(ids.size());
    return build_ploc(bounds, ids);
  };
  auto accel = make_bvh(test_device(), g, config);
  std::sort(calls.begin(), calls.end());  // one call per kind, in either order
  EXPECT_EQ(calls, (std::vector<std::size_t>{g.spheres.size(), g.triangles.size()}));
  expect_matches_reference(*accel, g, random_rays(g, 1000, 23));

  config.custom_builder = [](std::span<const Aabb> bounds, std::span<const std::uint32_t> ids) {
    return build_sah(bounds.first(bounds.size() - 1), ids.first(ids.size() - 1));
  };
  EXPECT_THROW(make_bvh(test_device(), g, config), Error);
}

TEST(Bvh, MatchesReferenceOnBunny) { expect_real_mesh_matches("stanford_bunny/bunny.obj"); }
TEST(Bvh, MatchesReferenceOnDragon) { expect_real_mesh_matches("stanford_dragon_100k/dragon.obj"); }
TEST(Bvh, MatchesReferenceOnSponza) { expect_real_mesh_matches("sponza/sponza.obj"); }

TEST(Bvh, BunnyFitsTheMemoryBudget) {
  Geometry g = load("stanford_bunny/bunny.obj");
  for (BvhBuilder b : {BvhBuilder::sah, BvhBuilder::ploc}) {
    Bvh8 bvh = flatten_bvh8(build_binary_bvh(g, config_for(b)), g);
    double bytes = static_cast<double>(bvh.nodes.size() * sizeof(Bvh8Node) + bvh.blocks.bytes());
    EXPECT_LE(bytes / static_cast<double>(g.triangles.size()), 64.0) << builder_name(b);
  }
}

TEST(Bvh, StackSizeRoundsUpToAMultipleOfEightOfAtLeast32) {
  EXPECT_EQ(bvh_kernel_stack_size(0), 32u);
  EXPECT_EQ(bvh_kernel_stack_size(32), 32u);
  EXPECT_EQ(bvh_kernel_stack_size(33), 40u);
  EXPECT_EQ(bvh_kernel_stack_size(37), 40u);
  EXPECT_EQ(bvh_kernel_stack_size(kBvhMaxStackSize), kBvhMaxStackSize);
}

TEST(Bvh, IsRegistered) {
  auto names = accel_names();
  EXPECT_NE(std::find(names.begin(), names.end(), "bvh"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "bvh-ploc"), names.end());
}

// The SAH builder tests the boxes in its parallel pass over them: the error
// names the first bad box in input order, whichever thread met it.
TEST(Bvh, SahBuilderNamesTheFirstBadBoxOnEveryThread) {
  const std::size_t n = 40000;
  std::vector<Aabb> bounds(n);
  std::vector<std::uint32_t> ids(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float x = static_cast<float>(i);
    bounds[i] = Aabb{{x, 0, 0}, {x + 1, 1, 1}};
    ids[i] = static_cast<std::uint32_t>(i + 7);
  }
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  const std::pair<int, float> corruptions[] = {{0, -inf}, {4, inf}, {2, nan}, {5, -1e30f}};  // bound index, value
  for (const auto& [bound, value] : corruptions)
    for (unsigned threads : {1u, 2u}) {
      std::vector<Aabb> bad = bounds;
      // two threads split the boxes at 20000: bad ones in both halves
      for (std::size_t i : {std::size_t(15000), std::size_t(17000), std::size_t(30001)})
        (bound < 3 ? bad[i].lower : bad[i].upper)[bound % 3] = value;
      try {
        build_sah(bad, ids, {.thread_count = threads});
        ADD_FAILURE() << "bound " << bound << " = " << value << " accepted";
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("the box of primitive 15007 has"), std::string::npos) << e.what();
      }
      // the same boxes as references filled by the caller
      auto refs = std::make_unique<SahRef[]>(n);
      for (std::size_t i = 0; i < n; ++i) refs[i] = SahRef::of(bad[i], ids[i]);
      try {
        build_sah(std::move(refs), n, {.thread_count = threads});
        ADD_FAILURE() << "bound " << bound << " = " << value << " accepted as a reference";
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("the box of primitive 15007 has"), std::string::npos) << e.what();
      }
    }
}

// build_binary_bvh fills the SAH builder's references and gathers their
// bounds in its own pass over the triangles (zero-area ones skipped in
// every part): the tree of the stored triangles' boxes and ids given to
// build_sah, and of the same references given to it with and without their
// bounds, on one thread and on two.
TEST(Bvh, SahOverFilledReferencesBuildsTheTreeOfTheBoxes) {
  Geometry g = random_soup(40000, 31);
  for (std::size_t i = 3; i < g.triangles.size(); i += 7) g.triangles[i].z = g.triangles[i].y;
  const BuildInputs in = triangle_inputs(g);
  ASSERT_LT(in.ids.size(), g.triangles.size() - g.triangles.size() / 8);
  for (unsigned threads : {1u, 2u}) {
    BvhConfig config;
    config.sah.thread_count = threads;
    std::vector<double> of_boxes, of_refs, of_geometry;
    canonical(build_sah(in.bounds, in.ids, config.sah), 0, of_boxes);
    auto refs = std::make_unique<SahRef[]>(in.ids.size());
    for (std::size_t i = 0; i < in.ids.size(); ++i) refs[i] = SahRef::of(in.bounds[i], in.ids[i]);
    auto bounded_refs = std::make_unique<SahRef[]>(in.ids.size());
    SahBounds bounds;
    for (std::size_t i = 0; i < in.ids.size(); ++i) bounds.add(bounded_refs[i] = refs[i]);
    canonical(build_sah(std::move(refs), in.ids.size(), config.sah), 0, of_refs);
    std::vector<double> of_bounded_refs;
    canonical(build_sah(std::move(bounded_refs), in.ids.size(), bounds, config.sah), 0, of_bounded_refs);
    EXPECT_TRUE(of_bounded_refs == of_boxes) << threads << " threads, references with their bounds";
    std::size_t stored = 0;
    canonical(build_binary_bvh(g, config, &stored), 0, of_geometry);
    EXPECT_EQ(stored, in.ids.size());
    EXPECT_TRUE(of_refs == of_boxes) << threads << " threads";
    EXPECT_TRUE(of_geometry == of_boxes) << threads << " threads";
  }
  EXPECT_THROW(build_sah(nullptr, 3), Error);
  EXPECT_EQ(build_sah(nullptr, 0).nodes.size(), 0u);
}

TEST(Bvh, BadBuilderInputIsAnError) {
  std::vector<Aabb> bounds(3, Aabb{{0, 0, 0}, {1, 1, 1}});
  std::vector<std::uint32_t> ids = {0, 1};
  EXPECT_THROW(build_sah(bounds, ids), Error);
  EXPECT_THROW(build_ploc(bounds, ids), Error);
  ids.push_back(2);
  bounds[1].upper.y = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(build_sah(bounds, ids), Error);
  EXPECT_THROW(build_ploc(bounds, ids), Error);
  bounds[1] = Aabb{{0, 2, 0}, {1, 1, 1}};  // lower > upper
  EXPECT_THROW(build_sah(bounds, ids), Error);
  bounds[1] = Aabb{{0, 0, 0}, {1, 1, 1}};
  EXPECT_THROW(build_sah(bounds, ids, {.bin_count = 1}), Error);
  EXPECT_THROW(build_sah(bounds, ids, {.max_leaf_size = 9}), Error);
  EXPECT_THROW(build_ploc(bounds, ids, {.search_radius = 0}), Error);
  EXPECT_THROW(build_ploc(bounds, ids, {.max_leaf_size = 0}), Error);
  try {
    build_sah(bounds, ids, {.node_cost = -1.0f});
    FAIL() << "negative node cost accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("node_cost"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(build_sah({}, {}).empty());
  EXPECT_TRUE(build_ploc({}, {}).empty());
}

TEST(Bvh, FlattenRejectsTreesThatDoNotMatchTheGeometry) {
  Geometry g = random_soup(20, 51);
  BuildTree tree = build_binary_bvh(g);
  BuildTree missing = tree;
  for (BuildNode& n : missing.nodes)
    if (n.is_leaf() && n.count > 1) {
      --n.count;
      break;
    }
  EXPECT_THROW(flatten_bvh8(missing, g), Error);
  BuildTree twice = tree;
  for (BuildNode& n : twice.nodes)
    if (n.is_leaf()) n.first = 0;
  EXPECT_THROW(flatten_bvh8(twice, g), Error);
  EXPECT_THROW(flatten_bvh8(BuildTree{}, g), Error);
}

// Soup and spheres enough for the gather to split the blocks over threads
// (at 512 blocks and more).
Geometry soup_with_spheres(std::uint32_t seed) {
  Geometry g = random_soup(20000, seed);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int i = 0; i < 5000; ++i) g.spheres.push_back({{unit(rng), unit(rng), unit(rng)}, 0.01f});
  return g;
}

template <class T, class Allocator>
bool same_bytes(const std::vector<T, Allocator>& a, const std::vector<T, Allocator>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

// Large enough (over 4096 binary nodes, both kinds) that the walk forms
// the subtrees below its top levels in parts, one thread or several.
TEST(Bvh, FlattenDoesNotDependOnTheThreads) {
  Geometry g = soup_with_spheres(20000, 4000, 52);
  BuildTree tree = build_binary_bvh(g);
  ASSERT_GE(tree.nodes.size(), 4096u);
  Bvh8 one = flatten_bvh8(tree, g, {.thread_count = 1});
  EXPECT_EQ(check_wide(one, g), "");
  for (unsigned threads : {2u, 3u}) {
    Bvh8 many = flatten_bvh8(tree, g, {.thread_count = threads});
    EXPECT_TRUE(same_bytes(one.nodes, many.nodes)) << threads << " threads";
    EXPECT_TRUE(same_bytes(one.blocks.triangles, many.blocks.triangles)) << threads << " threads";
    EXPECT_TRUE(same_bytes(one.blocks.spheres, many.blocks.spheres)) << threads << " threads";
    EXPECT_EQ(one.stack_size, many.stack_size);
    EXPECT_EQ(one.depth, many.depth);
  }
}

std::string flatten_error(const BuildTree& tree, const Geometry& g, unsigned threads) {
  try {
    flatten_bvh8(tree, g, {.thread_count = threads});
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// A mismatch met only by the second gather thread is found as well: a
// primitive in the first and the last block (each thread marks it once),
// and a last leaf that does not contain its primitive.
TEST(Bvh, FlattenRejectsMismatchesOnEveryThread) {
  Geometry g = soup_with_spheres(53);
  BuildTree tree = build_binary_bvh(g);
  // The primitive in lane 0 of the first and of the last triangle block, and
  // where the tree holds the latter; the walk (hence the blocks) does not
  // depend on which ids the leaves hold.
  auto ends = [&](const BuildTree& t) {
    Bvh8 bvh = flatten_bvh8(t, g, {.thread_count = 2});
    auto first = static_cast<std::uint32_t>(bvh.blocks.triangles.front().prim[0]);
    auto last = static_cast<std::uint32_t>(bvh.blocks.triangles.back().prim[0]);
    auto at = static_cast<std::size_t>(std::find(t.prims.begin(), t.prims.end(), last) - t.prims.begin());
    return std::pair(first, at);
  };

  // Every box the scene's, so that no box check objects to the moved id.
  BuildTree twice = tree;
  const Aabb scene = g.bounds();
  for (BuildNode& n : twice.nodes) n.bounds = scene;
  auto [first, at] = ends(twice);
  twice.prims[at] = first;
  std::string error = flatten_error(twice, g, 2);
  EXPECT_NE(error.find("primitive " + std::to_string(first) + " is in two leaves"), std::string::npos) << error;

  BuildTree outside = tree;
  at = ends(tree).second;
  for (BuildNode& n : outside.nodes)
    if (n.is_leaf() && n.first <= at && at < n.first + n.count) n.bounds.upper = n.bounds.lower;
  error = flatten_error(outside, g, 2);
  EXPECT_NE(error.find("does not contain primitive " + std::to_string(outside.prims[at])), std::string::npos)
      << error;
}

// A chain of binary nodes (what a builder without a depth bound makes of
// nested boxes) needs more stack than the kernel may have: refused.
TEST(Bvh, FlattenRefusesTreesTooDeepForTheStack) {
  constexpr std::uint32_t n = 20000;
  Geometry g = nested_triangles(n);
  BuildTree chain;
  for (std::uint32_t i = 0; i < n; ++i) chain.prims.push_back(i);
  Aabb all = g.bounds();
  for (std::uint32_t i = 0; i + 1 < n; ++i) {
    BuildNode inner;
    inner.bounds = all;
    inner.child[0] = 2 * i + 1;  // leaf
    inner.child[1] = 2 * i + 2;  // next inner node (or the last leaf)
    chain.nodes.push_back(inner);
    BuildNode leaf;
    leaf.bounds = all;
    leaf.first = i;
    leaf.count = 1;
    chain.nodes.push_back(leaf);
  }
  BuildNode last;
  last.bounds = all;
  last.first = n - 1;
  last.count = 1;
  chain.nodes.push_back(last);
  try {
    flatten_bvh8(chain, g);
    FAIL() << "a tree deeper than the stack was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("stack"), std::string::npos) << e.what();
  }
}

// Shadow-like rays for the occluder cache: `count` rays from points of a
// small patch below the soup towards one point above it, in patch order (runs
// of neighbours share occluders); every third ray is instead a random one,
// every fifth has its tmax cut to just before its first occluder (so the
// previous ray's occluder, which the cache tries first, must not answer),
// and every 97th is invalid (tmin > tmax: a miss that leaves the cache as it
// is).
std::vector<Ray> occlusion_rays(const Geometry& g, std::size_t count, std::uint32_t seed) {
  std::vector<Ray> random = random_rays(g, count, seed);
  std::vector<Ray> rays;
  const glm::vec3 target(0.5f, 0.5f, 2.0f);
  for (std::size_t i = 0; i < count; ++i) {
    const float u = static_cast<float>(i % 37) / 37.0f, v = static_cast<float>(i / 37) / 37.0f;
    const glm::vec3 origin(0.3f + 0.4f * u, 0.3f + 0.4f * v, -1.0f);
    Ray r = i % 3 == 2 ? random[i] : Ray{origin.x, origin.y, origin.z, target.x - origin.x, target.y - origin.y,
                                         target.z - origin.z, 0.0f, 1.0f};
    if (i % 5 == 4) {
      Hit first = reference_closest(g, r);
      if (first.prim >= 0) r.tmax = 0.999f * first.t;
    }
    if (i % 97 == 96) r.tmin = r.tmax + 1.0f;
    rays.push_back(r);
  }
  return rays;
}

// Occlusion with runs of rays (or packets of 8) per work-item, each first
// tested against the previous one's occluder: every answer is a valid any
// hit (an occluder the double-precision reference confirms, or a miss only
// where it finds none), and hit or miss is that of one ray per work-item,
// for runs that do and do not divide the ray or packet count, triangles
// and spheres, single rays and packets; the kd-tree, the BSP, the grid and
// the octrees, whose any-hit kernels have occluder runs too, alike.
TEST(Bvh, OccluderRunsKeepEveryOcclusionAnswer) {
  Geometry g = soup_with_spheres(3000, 200, 71);
  for (std::size_t count : {std::size_t{1}, std::size_t{7}, std::size_t{1369}}) {
    std::vector<Ray> rays = occlusion_rays(g, count, 72);
    auto single = make_accel(test_device(), "bvh:occluder_run=1", g);
    std::vector<Hit> want = run_query(*single, rays, Query::any);
    std::size_t blocked = 0;
    for (const Hit& h : want) blocked += h.prim >= 0;
    if (count > 1000) {
      EXPECT_GT(blocked, count / 4) << "too few occluded rays to exercise the cache";
      EXPECT_LT(blocked, count - count / 4) << "too few unoccluded rays";
    }
    for (const char* spec : {"bvh:occluder_run=2", "bvh:occluder_run=3", "bvh:occluder_run=16",
                             "bvh:occluder_run=1024", "bvh", "bvh-ploc:occluder_run=5", "bvh-packet:occluder_run=1",
                             "bvh-packet:occluder_run=3", "bvh-packet", "kdtree:occluder_run=3", "kdtree",
                             "bsp:occluder_run=7", "bsp", "grid:occluder_run=3", "grid", "octree:occluder_run=6",
                             "octree", "octree-ptr:occluder_run=2", "octree-ptr", "octree-r"}) {
      auto accel = make_accel(test_device(), spec, g);
      std::vector<Hit> got = run_query(*accel, rays, Query::any);
      std::size_t failures = 0, differ = 0;
      auto report = judge_all(g, rays, got, Query::any, &failures);
      EXPECT_EQ(failures, 0u) << spec << " on " << count << " rays: " << (report.empty() ? "" : report[0]);
      for (std::size_t i = 0; i < rays.size(); ++i) differ += (got[i].prim >= 0) != (want[i].prim >= 0);
      EXPECT_EQ(differ, 0u) << spec << " on " << count << " rays";
    }
  }
}

TEST(Bvh, OccluderRunFollowsTheDevice) {
  DeviceInfo cpu, gpu;
  cpu.type = "cpu";
  gpu.type = "gpu";
  EXPECT_EQ(occluder_run_for(0, cpu), kCpuOccluderRun);
  EXPECT_EQ(occluder_run_for(0, gpu), 1u);
  EXPECT_EQ(occluder_run_for(5, cpu), 5u);
  EXPECT_EQ(occluder_run_for(5, gpu), 5u);
}

TEST(Bvh, PacketsServeCoherentCallsOnCpuDevicesOnly) {
  DeviceInfo cpu, gpu, accelerator;
  cpu.type = "cpu";
  gpu.type = "gpu";
  accelerator.type = "accelerator";
  EXPECT_TRUE(packets_for_coherent_calls(cpu));
  EXPECT_FALSE(packets_for_coherent_calls(gpu));
  EXPECT_FALSE(packets_for_coherent_calls(accelerator));
}

TEST(Bvh, ReportsStats) {
  Geometry g = random_soup(1000, 61);
  auto accel = make_accel(test_device(), "bvh", g);
  const AccelStats& s = accel->stats();
  EXPECT_EQ(s.primitive_count, 1000u);
  EXPECT_GT(s.node_count, 0u);
  EXPECT_GE(s.leaf_count, 1000u / 8);
  EXPECT_EQ(s.device_bytes, s.node_count * sizeof(Bvh8Node) + s.leaf_count * sizeof(TriangleBlock));
  EXPECT_GT(s.build_ms, 0.0);
}

}  // namespace
}  // namespace rtcl::test
