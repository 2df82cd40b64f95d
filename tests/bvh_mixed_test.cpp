// The mixed-volume BVH ("bvh-mixed", rtcl/accel/bvh_mixed.hpp): the spheres,
// k-DOP slabs and OBBs it chooses contain everything below them, the choice
// follows the costs, and its answers agree with brute force bit for bit and
// pass the double-precision reference, on rays aimed at the vertices and
// edges the volumes pass through. It also runs in every registry-wide suite
// (accel_names()).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>

#include "rtcl/accel/bvh_mixed.hpp"
#include "rtcl/bounds/kdop.hpp"
#include "rtcl/error.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/fixtures.hpp"
#include "support/reference.hpp"

namespace rtcl::test {
namespace {


// Every triangle vertex below child reference `ref`, read back from the
// blocks (the leaves' contents).
void vertices_below(const Bvh8& bvh, rtcl_i32 ref, std::vector<glm::dvec3>& out) {
  if (ref >= 0) {
    for (rtcl_i32 c : bvh.nodes[static_cast<std::size_t>(ref)].child)
      if (c != RTCL_CHILD_EMPTY) vertices_below(bvh, c, out);
    return;
  }
  const TriangleBlock& b = bvh.blocks.triangles[static_cast<std::size_t>((~ref) >> 1)];
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane)
    if (b.prim[lane] >= 0)
      for (int v = 0; v < 3; ++v) out.emplace_back(b.v[v][0][lane], b.v[v][1][lane], b.v[v][2][lane]);
}

// Specs with one kind free (cost 0: wherever it cuts the box) and the others
// off, and all kinds free (each node takes the one that cuts most).
const std::vector<std::string>& forced_specs() {
  static const std::vector<std::string> specs = {
      "bvh-mixed:sphere_cost=0,kdop_cost=64,obb_cost=64", "bvh-mixed:sphere_cost=64,kdop_cost=0,obb_cost=64",
      "bvh-mixed:sphere_cost=64,kdop_cost=64,obb_cost=0", "bvh-mixed:sphere_cost=0,kdop_cost=0,obb_cost=0"};
  return specs;
}

VolumeCosts only(int kind) {
  VolumeCosts c{64.0f, 64.0f, 64.0f, 4.0f};
  if (kind == RTCL_FILTER_SPHERE) c.sphere = 0.0f;
  if (kind == RTCL_FILTER_KDOP) c.kdop = 0.0f;
  if (kind == RTCL_FILTER_OBB) c.obb = 0.0f;
  return c;
}

// Whether lane `lane` of the record holds a volume, and whether point p
// lies in it (double arithmetic on the stored floats).
bool sphere_lane(const Bvh8Spheres& s, int lane) { return s.r[lane] >= 0.0f; }
bool in_sphere(const Bvh8Spheres& s, int lane, const glm::dvec3& p) {
  return glm::length(p - glm::dvec3(s.cx[lane], s.cy[lane], s.cz[lane])) <= static_cast<double>(s.r[lane]);
}
bool kdop_lane(const Bvh8Kdop& k, int lane) { return k.d_near[0][lane] > -std::numeric_limits<float>::max(); }
bool in_kdop(const Bvh8Kdop& k, int lane, const glm::dvec3& p) {
  std::vector<glm::vec3> dirs = kdop_directions(7);
  for (int j = 0; j < RTCL_KDOP_FILTER_SLABS; ++j) {
    double d = glm::dot(glm::dvec3(dirs[static_cast<std::size_t>(3 + j)]), p);
    if (!(d >= k.d_near[j][lane] && d <= k.d_far[j][lane])) return false;
  }
  return true;
}
bool obb_lane(const Bvh8Obb& o, int lane) { return o.d_near[0][lane] > -std::numeric_limits<float>::max(); }
bool in_obb(const Bvh8Obb& o, int lane, const glm::dvec3& p) {
  for (int i = 0; i < 3; ++i) {
    glm::dvec3 u(o.axis[3 * i][lane], o.axis[3 * i + 1][lane], o.axis[3 * i + 2][lane]);
    double d = glm::dot(u, p);
    if (!(d >= o.d_near[i][lane] && d <= o.d_far[i][lane])) return false;
  }
  return true;
}

// Checks every used lane of every chosen record of `kind` against every
// triangle vertex below its child; returns the used lanes.
template <class Record>
std::size_t check_contains(const Bvh8& bvh, const BvhVolumeFilters& f, int kind, const std::vector<Record>& records,
                           bool (*used)(const Record&, int), bool (*inside)(const Record&, int, const glm::dvec3&)) {
  std::size_t lanes = 0;
  for (std::size_t n = 0; n < bvh.nodes.size(); ++n) {
    rtcl_i32 ref = f.filter_of[n];
    if (ref == RTCL_FILTER_NONE || RTCL_FILTER_KIND(ref) != kind) continue;
    const Record& r = records.at(static_cast<std::size_t>(RTCL_FILTER_INDEX(ref)));
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
      if (!used(r, lane)) continue;
      ++lanes;
      std::vector<glm::dvec3> points;
      vertices_below(bvh, bvh.nodes[n].child[lane], points);
      EXPECT_FALSE(points.empty());
      for (const glm::dvec3& p : points)
        if (!inside(r, lane, p)) {
          ADD_FAILURE() << "kind " << kind << " node " << n << " lane " << lane << " misses vertex " << p.x << ", "
                        << p.y << ", " << p.z;
          return lanes;
        }
    }
  }
  return lanes;
}

TEST(BvhMixed, EveryFilterVolumeContainsItsChildsVertices) {
  std::size_t total[kFilterKinds] = {};
  for (const Geometry& g : {random_soup(3000, 7), random_soup(800, 13, 0.05f, 1.0f, glm::vec3(3.0e4f, -2.0e4f, 1.0e4f))}) {
    Bvh8 bvh = flatten_bvh8(build_binary_bvh(g), g);
    for (int kind : {RTCL_FILTER_SPHERE, RTCL_FILTER_KDOP, RTCL_FILTER_OBB}) {
      BvhVolumeFilters f = choose_volume_filters(bvh, only(kind), g.source);
      ASSERT_EQ(f.filter_of.size(), bvh.nodes.size());
      std::size_t lanes = kind == RTCL_FILTER_SPHERE ? check_contains(bvh, f, kind, f.spheres, sphere_lane, in_sphere)
                          : kind == RTCL_FILTER_KDOP ? check_contains(bvh, f, kind, f.kdops, kdop_lane, in_kdop)
                                                     : check_contains(bvh, f, kind, f.obbs, obb_lane, in_obb);
      total[kind] += lanes;
      EXPECT_EQ(lanes, f.lanes[kind]) << "kind " << kind;
      // One kind free, the others off: only that kind's records.
      EXPECT_TRUE(f.spheres.empty() || kind == RTCL_FILTER_SPHERE);
      EXPECT_TRUE(f.kdops.empty() || kind == RTCL_FILTER_KDOP);
      EXPECT_TRUE(f.obbs.empty() || kind == RTCL_FILTER_OBB);
    }
  }
  for (int kind = 0; kind < kFilterKinds; ++kind) EXPECT_GT(total[kind], 0u) << "kind " << kind;
}

TEST(BvhMixed, TheKernelsDiagonalsAreTheKdopDirections) {
  std::vector<glm::vec3> dirs = kdop_directions(7);
  const float c = RTCL_KDOP_DIAGONAL;
  const glm::vec3 kernel[RTCL_KDOP_FILTER_SLABS] = {{c, c, c}, {c, c, -c}, {c, -c, c}, {-c, c, c}};
  for (int j = 0; j < RTCL_KDOP_FILTER_SLABS; ++j) EXPECT_EQ(dirs[static_cast<std::size_t>(3 + j)], kernel[j]) << j;
}

TEST(BvhMixed, TheChoiceFollowsTheCosts) {
  Geometry g = random_soup(3000, 29);
  Bvh8 bvh = flatten_bvh8(build_binary_bvh(g), g);
  BvhVolumeFilters free_filters = choose_volume_filters(bvh, {0.0f, 0.0f, 0.0f, VolumeCosts{}.block}, g.source);
  BvhVolumeFilters costly = choose_volume_filters(bvh, {64.0f, 64.0f, 64.0f, VolumeCosts{}.block}, g.source);
  BvhVolumeFilters measured = choose_volume_filters(bvh, {}, g.source);
  EXPECT_TRUE(costly.empty());
  EXPECT_EQ(costly.device_bytes(), 0u);
  std::size_t free_records = free_filters.spheres.size() + free_filters.kdops.size() + free_filters.obbs.size();
  std::size_t measured_records = measured.spheres.size() + measured.kdops.size() + measured.obbs.size();
  EXPECT_GT(free_records, measured_records);
  // Boxes alone are always a candidate: the chosen cost never exceeds theirs.
  for (const BvhVolumeFilters* f : {&free_filters, &costly, &measured}) {
    EXPECT_LE(f->chosen_cost, f->aabb_cost);
    EXPECT_GT(f->aabb_cost, 1.0);
  }
  EXPECT_LT(free_filters.chosen_cost, free_filters.aabb_cost);
  EXPECT_DOUBLE_EQ(costly.chosen_cost, costly.aabb_cost);
  EXPECT_DOUBLE_EQ(measured.aabb_cost, costly.aabb_cost);
}

TEST(BvhMixed, BadCostsAreAnError) {
  Geometry g = random_soup(50, 3);
  Bvh8 bvh = flatten_bvh8(build_binary_bvh(g), g);
  EXPECT_THROW(choose_volume_filters(bvh, {-1.0f, 1.0f, 1.0f, 4.0f}, g.source), Error);
  EXPECT_THROW(choose_volume_filters(bvh, {1.0f, 1.0f, std::numeric_limits<float>::infinity(), 4.0f}, g.source),
               Error);
  EXPECT_THROW(choose_volume_filters(bvh, {1.0f, 1.0f, 1.0f, std::numeric_limits<float>::quiet_NaN()}, g.source),
               Error);
  for (const char* option : {"sphere_cost", "kdop_cost", "obb_cost"}) {
    try {
      make_accel(test_device(), std::string("bvh-mixed:") + option + "=-1", g);
      ADD_FAILURE() << "a negative " << option << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(option), std::string::npos) << e.what();
    }
  }
}

// Rays from outside aimed exactly at vertices and edge midpoints (the points
// a tight volume passes through), axis-parallel ones with ±0 components,
// ones parallel to a k-DOP diagonal plane (dot(n_j, d) = 0 exactly), and
// random ones.
std::vector<Ray> aimed_rays(const Geometry& g, std::uint32_t seed, int aimed = 400) {
  std::vector<Ray> rays = random_rays(g, 300, seed);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> pick(0, g.triangles.size() - 1);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  Aabb box = g.bounds();
  float reach = glm::length(box.extent()) * 2.0f;
  const glm::vec3 parallel[6] = {{1, -1, 0}, {0, 1, -1}, {-1, 0, 1}, {1, 1, 0}, {0, -1, -1}, {1, 0, 1}};
  for (int i = 0; i < aimed; ++i) {
    const glm::uvec3& t = g.triangles[pick(rng)];
    glm::vec3 v0 = g.vertices[t.x], v1 = g.vertices[t.y], v2 = g.vertices[t.z];
    glm::vec3 target = i % 3 == 0 ? v0 : i % 3 == 1 ? 0.5f * (v0 + v1) : v2;
    glm::vec3 d = glm::normalize(glm::vec3(normal(rng), normal(rng), normal(rng)));
    glm::vec3 o = target - reach * d;
    rays.push_back({o.x, o.y, o.z, d.x, d.y, d.z, 0.0f, kInf});
    // Axis-parallel, the other components +0 or -0.
    float zero = (i & 1) ? -0.0f : 0.0f;
    glm::vec3 dir(zero);
    dir[i % 3] = (i & 2) ? 1.0f : -1.0f;
    glm::vec3 from = target;
    from[i % 3] -= reach * dir[i % 3];
    rays.push_back({from.x, from.y, from.z, dir.x, dir.y, dir.z, 0.0f, kInf});
    // Parallel to two of the diagonal planes, the zero component signed.
    glm::vec3 p = parallel[i % 6];
    for (int a = 0; a < 3; ++a)
      if (p[a] == 0.0f) p[a] = zero;
    glm::vec3 start = target - reach * p;
    rays.push_back({start.x, start.y, start.z, p.x, p.y, p.z, 0.0f, kInf});
  }
  return rays;
}

// The registry-wide rule (tests/support/everywhere.cpp): the same hit or
// miss and, for closest hits, the same t as brute force at the same level;
// where the primitive differs (another one at that t, sharing an edge or a
// vertex) the answer must pass the double-precision reference's judge.
// Brute force runs once for all specs.
void expect_agrees(const Geometry& g, const std::vector<Ray>& rays, const std::vector<std::string>& specs) {
  auto brute = make_accel(test_device(), "brute", g);
  std::vector<std::unique_ptr<Accel>> mixed;
  for (const std::string& spec : specs) mixed.push_back(make_accel(test_device(), spec, g));
  for (Query q : {Query::closest, Query::any}) {
    std::vector<Hit> want = run_query(*brute, rays, q);
    for (std::size_t m = 0; m < specs.size(); ++m) {
      const std::string& spec = specs[m];
      std::vector<Hit> got = run_query(*mixed[m], rays, q);
      ASSERT_EQ(got.size(), rays.size());
      std::size_t differ = 0, judged = 0;
      for (std::size_t i = 0; i < rays.size(); ++i) {
        bool same = (got[i].prim < 0) == (want[i].prim < 0) &&
                    (q == Query::any || got[i].prim < 0 || got[i].t == want[i].t);
        if (!same && differ++ < 3)
          ADD_FAILURE() << spec << (q == Query::closest ? " closest" : " any") << " ray " << i << ": t " << got[i].t
                        << " prim " << got[i].prim << ", brute force t " << want[i].t << " prim " << want[i].prim;
        if (same && got[i].prim != want[i].prim) {
          ++judged;
          std::string verdict = judge(g, rays[i], got[i], q);
          EXPECT_TRUE(verdict.empty()) << spec << " ray " << i << ": " << verdict;
        }
      }
      EXPECT_EQ(differ, 0u) << spec;
      if (q == Query::closest) EXPECT_LT(judged, rays.size()) << spec;
    }
  }
}

TEST(BvhMixed, AgreesWithBruteForceOnASoupWithFiltersEverywhere) {
  Geometry g = random_soup(3000, 11);
  expect_agrees(g, aimed_rays(g, 5), forced_specs());
}

TEST(BvhMixed, AgreesWithBruteForceOnTheBunny) {
  Geometry g = bunny();
  expect_agrees(g, aimed_rays(g, 9, 300), {forced_specs().back(), "bvh-mixed"});
}

TEST(BvhMixed, FarFromTheOriginStaysConservative) {
  Geometry g = random_soup(1500, 13, 0.05f, 1.0f, glm::vec3(3.0e4f, -2.0e4f, 1.0e4f));
  expect_agrees(g, aimed_rays(g, 17), forced_specs());
}

// At every precision level the filters only drop children that hold no
// hit, and bvh-mixed builds the tree of "bvh" and runs its kernel: with
// every filter forced, the answers are those of "bvh" at that level, bit for
// bit (same primitive, t, u, v), for both queries (any hit: both one ray per
// work-item, without the occluder cache, so the same occluder).
TEST(BvhMixed, ForcedFiltersAnswerAsThePlainBvhAtEveryLevel) {
  for (const Geometry& g : {random_soup(1500, 31), random_soup(800, 37, 0.05f, 1.0f, glm::vec3(-4.0e4f, 1.0e4f, 2.0e4f))}) {
    std::vector<Ray> rays = aimed_rays(g, 41, 200);
    for (Precision level : {Precision::fast, Precision::robust, Precision::exact}) {
      auto plain = make_accel(test_device(), "bvh:occluder_run=1", g, {level});
      auto mixed = make_accel(test_device(), forced_specs().back() + ",occluder_run=1", g, {level});
      for (Query q : {Query::closest, Query::any}) {
        std::vector<Hit> want = run_query(*plain, rays, q), got = run_query(*mixed, rays, q);
        std::size_t differ = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
          bool same = got[i].prim == want[i].prim &&
                      (q == Query::any || (got[i].t == want[i].t && got[i].u == want[i].u && got[i].v == want[i].v));
          if (!same && differ++ < 3)
            ADD_FAILURE() << precision_name(level) << (q == Query::closest ? " closest" : " any") << " on " << g.source
                          << " ray " << i << ": prim " << got[i].prim << " t " << got[i].t << ", bvh prim "
                          << want[i].prim << " t " << want[i].t;
        }
        EXPECT_EQ(differ, 0u) << precision_name(level) << " on " << g.source;
      }
    }
  }
}

TEST(BvhMixed, WithoutFiltersItIsThePlainKernel) {
  Geometry g = random_soup(500, 19);
  const std::string spec = "bvh-mixed:sphere_cost=64,kdop_cost=64,obb_cost=64";
  auto accel = make_accel(test_device(), spec, g);
  EXPECT_EQ(accel->stats().device_bytes,
            accel->stats().node_count * sizeof(Bvh8Node) + accel->stats().leaf_count * sizeof(TriangleBlock));
  expect_agrees(g, aimed_rays(g, 23), {spec});
}

}  // namespace
}  // namespace rtcl::test
