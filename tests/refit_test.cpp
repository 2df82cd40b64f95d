// Accel::refit (src/rtcl/accel/refit.cpp): a BVH refitted to moved vertices
// answers as one built over them does: the double-precision reference
// judges its answers at every precision level, both queries and both
// kernels, and at robust and exact its closest t equals brute force's over
// the moved vertices bit for bit (every structure runs the same triangle
// test, so a rebuild gives that t too). Plus what refit refuses and rejects,
// and the cost it reports.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/closed_meshes.hpp"
#include "support/error_of.hpp"
#include "support/everywhere.hpp"
#include "support/fixtures.hpp"
#include "support/reference.hpp"

namespace rtcl::test {
namespace {

using everywhere::describe;
using everywhere::disagreements_with_brute;
using everywhere::expect_at_level;
using everywhere::query_name;

// The structures Accel::refit supports, with the presplit build (a triangle
// in several blocks, leaf boxes clipped at the build).
const std::vector<std::string> kRefittable = {"bvh", "bvh-ploc", "bvh-packet", "bvh:presplit=1"};

// Rays that graze the moved primitives' boxes: axis-parallel through a
// vertex, in the planes of a box's faces, along a box's edges (the
// refitted node boxes must contain them exactly).
std::vector<Ray> box_grazing_rays(const Geometry& g, std::size_t every, std::uint32_t seed) {
  std::vector<Ray> rays;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  const float reach = 2.0f * std::max({g.bounds().extent().x, g.bounds().extent().y, g.bounds().extent().z});
  for (std::size_t t = 0; t < g.triangles.size(); t += every) {
    const Aabb box = g.primitive_bounds(t);
    const glm::vec3 v = g.vertices[g.triangles[t].x];
    for (int axis = 0; axis < 3; ++axis) {
      glm::vec3 o = v, d(0.0f);
      o[axis] -= reach;
      d[axis] = 1.0f;
      rays.push_back(make_ray(o, d));
      glm::vec3 in_plane(unit(rng), unit(rng), unit(rng));
      in_plane[axis] = 0.0f;
      o = v - reach * in_plane;
      o[axis] = box.lower[axis];
      rays.push_back(make_ray(o, in_plane));
      o[axis] = box.upper[axis];
      rays.push_back(make_ray(o, in_plane));
      o = box.upper;
      o[axis] += reach;
      rays.push_back(make_ray(o, -d));
    }
  }
  return rays;
}

// Builds every refittable structure over `built`, refits it to `moved`
// (first to `detour`, when given, so that a second refit reuses the first's
// buffers) and checks its answers to `rays` at every level.
void expect_refit_answers(const Geometry& built, const Geometry& moved, const std::vector<Ray>& rays,
                          const Geometry* detour = nullptr) {
  const Device& device = test_device();
  const std::vector<Hit> references = reference_closest_all(moved, rays);
  for (Precision level : test_precisions()) {
    AccelConfig config{level, {}, ScatteredSort::never};
    auto brute = make_accel(device, "brute", moved, config);
    const std::vector<Hit> brute_hits[2] = {run_query(*brute, rays, Query::closest), run_query(*brute, rays, Query::any)};
    for (const std::string& name : kRefittable) {
      auto accel = make_accel(device, name, built, config);
      if (detour) ASSERT_FALSE(accel->refit(*detour).refused);
      const RefitStats stats = accel->refit(moved);
      ASSERT_FALSE(stats.refused) << stats.reason;
      for (Query query : {Query::closest, Query::any}) {
        const std::vector<Hit>& expected = brute_hits[query == Query::closest ? 0 : 1];
        for (Coherence coherence : {Coherence::incoherent, Coherence::coherent}) {
          if (coherence == Coherence::coherent &&
              accel->rays_per_work_item(coherence) == accel->rays_per_work_item(Coherence::incoherent))
            continue;
          const std::string what = name + " " + std::string(precision_name(level)) + " " + query_name(query) +
                                   (coherence == Coherence::coherent ? " coherent" : "") + " refitted to " +
                                   moved.source;
          SCOPED_TRACE(what);
          const std::vector<Hit> hits = run_query(*accel, rays, query, coherence);
          expect_at_level(level, false, what, [&] {
            std::size_t failures = 0;
            std::string first;
            const std::size_t disagreements = disagreements_with_brute(rays, hits, expected, query, &first);
            if (level != Precision::fast)
              EXPECT_EQ(disagreements, 0u) << "of " << rays.size() << " rays; first: " << first;
            auto report = judge_all(moved, rays, hits, query, references, &failures);
            EXPECT_EQ(failures, 0u) << "answers the double-precision reference rejects; first: "
                                    << (report.empty() ? "" : report[0]);
          });
        }
      }
    }
  }
}

TEST(Refit, BunnyAfterASineDeformationAnswersAsARebuild) {
  const Geometry built = bunny();
  Geometry moved = sine_deformed(built, 0.03f, 1.5f);
  moved.source = "bunny, sine-deformed";
  const Geometry detour = sine_deformed(built, -0.05f, 0.7f);
  std::vector<Ray> rays = random_rays(moved, 1500, 41);
  const std::vector<Ray> grazing = box_grazing_rays(moved, 400, 5);
  rays.insert(rays.end(), grazing.begin(), grazing.end());
  expect_refit_answers(built, moved, rays, &detour);
}

TEST(Refit, SoupWithSpheresAfterASineDeformationAnswersAsARebuild) {
  Geometry built = random_soup(3000, 7, 0.04f);
  built.spheres = {{{0.3f, 0.4f, 0.5f}, 0.08f}, {{0.7f, 0.2f, 0.6f}, 0.05f}};
  Geometry moved = sine_deformed(built, 0.08f, 2.0f);
  moved.spheres = built.spheres;
  moved.source = "soup, sine-deformed";
  std::vector<Ray> rays = random_rays(moved, 2000, 9);
  const std::vector<Ray> grazing = box_grazing_rays(moved, 10, 6);
  rays.insert(rays.end(), grazing.begin(), grazing.end());
  expect_refit_answers(built, moved, rays);
}

// The triangles should stay the build's; when they change (here: the
// corners of every triangle rotated, and triangles exchanged in pairs), the
// refit reads them again, and the tree, though worse, answers right.
TEST(Refit, ChangedTrianglesAreReadAgain) {
  const Geometry built = random_soup(2000, 13, 0.05f);
  const Geometry detour = sine_deformed(built, 0.02f, 1.0f);
  Geometry moved = sine_deformed(built, 0.05f, 1.5f);
  moved.source = "soup with other triangles";
  for (glm::uvec3& t : moved.triangles) t = glm::uvec3(t.y, t.z, t.x);
  for (std::size_t i = 0; i + 1 < moved.triangles.size(); i += 2) std::swap(moved.triangles[i], moved.triangles[i + 1]);
  expect_refit_answers(built, moved, random_rays(moved, 1500, 14), &detour);
}

TEST(Refit, TrianglesThatLoseTheirAreaAreMissedAsTheReferenceSkipsThem) {
  Geometry built = random_soup(500, 12, 0.1f);
  Geometry moved = built;
  moved.source = "soup with collapsed triangles";
  std::vector<Ray> rays;
  for (std::size_t t = 0; t < built.triangles.size(); t += 7) {
    const glm::uvec3 tri = built.triangles[t];
    moved.vertices[tri.z] = 0.5f * (moved.vertices[tri.x] + moved.vertices[tri.y]);  // collinear: no area
    const glm::vec3 c = (built.vertices[tri.x] + built.vertices[tri.y] + built.vertices[tri.z]) / 3.0f;
    rays.push_back(make_ray(c + glm::vec3(0.0f, 0.0f, 2.0f), glm::vec3(0.0f, 0.0f, -1.0f)));
  }
  const std::vector<Ray> more = random_rays(moved, 500, 3);
  rays.insert(rays.end(), more.begin(), more.end());
  expect_refit_answers(built, moved, rays);
}

// A closed mesh moved by a smooth radial field stays closed and star-shaped
// from its centre: rays from there through every vertex and edge midpoint
// must hit it (no leak through the refitted blocks' shared edges).
TEST(Refit, ClosedMeshStaysLeakFreeAfterRefit) {
  const Geometry built = icosphere(3, 1.0f);
  Geometry moved = built;
  for (glm::vec3& v : moved.vertices)
    v *= 1.0f + 0.25f * std::sin(3.0f * v.x) * std::cos(2.0f * v.y + 0.5f * v.z);
  moved.source = "icosphere, radially deformed";
  std::vector<Ray> rays;
  const glm::vec3 centre(0.0f);
  for (const glm::vec3& v : moved.vertices) rays.push_back(make_ray(centre, v));
  for (auto [a, b] : unique_edges(moved)) rays.push_back(make_ray(centre, 0.5f * (moved.vertices[a] + moved.vertices[b])));
  const Device& device = test_device();
  for (Precision level : test_precisions())
    for (const std::string& name : kRefittable) {
      auto accel = make_accel(device, name, built, {level});
      ASSERT_FALSE(accel->refit(moved).refused);
      for (Query query : {Query::closest, Query::any}) {
        const std::string what = name + " " + std::string(precision_name(level)) + " " + query_name(query);
        SCOPED_TRACE(what);
        const std::vector<Hit> hits = run_query(*accel, rays, query);
        expect_at_level(level, false, what, [&] {
          std::size_t leaks = 0;
          std::string first;
          for (std::size_t i = 0; i < rays.size(); ++i)
            if (hits[i].prim < 0 && leaks++ == 0) first = describe(rays[i]);
          EXPECT_EQ(leaks, 0u) << "of " << rays.size() << " rays from inside; first: " << first;
        });
      }
    }
}

TEST(Refit, ZeroAreaTriangleThatGainsAreaIsRefusedAndRebuilt) {
  const Device& device = test_device();
  const Geometry built = with_a_degenerate_triangle();
  Geometry moved = built;
  moved.vertices[5] = {3, 1, 0};  // triangle 2 now spans (2,0)-(3,1)-(4,0)
  const Ray down = make_ray({3.0f, 0.4f, 1.0f}, {0.0f, 0.0f, -1.0f});  // meets triangle 2 only
  const Ray old_hit = make_ray({0.25f, 0.25f, 1.0f}, {0.0f, 0.0f, -1.0f});
  ASSERT_EQ(reference_closest(moved, down).prim, 2);
  for (const std::string& name : kRefittable) {
    SCOPED_TRACE(name);
    std::unique_ptr<Accel> accel = make_accel(device, name, built);
    const RefitStats stats = accel->refit(moved);
    EXPECT_TRUE(stats.refused);
    EXPECT_TRUE(stats.needs_rebuild);
    EXPECT_NE(stats.reason.find("triangle 2"), std::string::npos) << stats.reason;
    // Unchanged: it still answers for the built vertices.
    EXPECT_EQ(run_query(*accel, {down}, Query::closest)[0].prim, -1);
    EXPECT_EQ(run_query(*accel, {old_hit}, Query::closest)[0].prim, 0);
    const RefitStats rebuilt = refit_or_rebuild(accel, name, moved);
    EXPECT_TRUE(rebuilt.rebuilt);
    EXPECT_FALSE(rebuilt.needs_rebuild);
    EXPECT_EQ(run_query(*accel, {down}, Query::closest)[0].prim, 2);
  }
}

TEST(Refit, BadInputIsAnErrorNamingItAndChangesNothing) {
  const Device& device = test_device();
  Geometry built = random_soup(200, 3);
  built.spheres = {{{0.5f, 0.5f, 0.5f}, 0.1f}};
  const std::vector<Ray> rays = random_rays(built, 200, 4);
  auto accel = make_accel(device, "bvh", built);
  const std::vector<Hit> before = run_query(*accel, rays, Query::closest);
  const Geometry moved = sine_deformed(built, 0.05f, 1.0f);
  struct Case {
    const char* expect;
    std::function<void(Geometry&)> spoil;
  };
  const std::vector<Case> cases = {
      {"vertices holds 601 vertices, the structure was built over 600",
       [](Geometry& g) { g.vertices.push_back(glm::vec3(0.0f)); }},
      {"triangles holds 199 triangles, the structure was built over 200", [](Geometry& g) { g.triangles.pop_back(); }},
      {"spheres holds 0 spheres", [](Geometry& g) { g.spheres.clear(); }},
      {"spheres[0] differs from the build's", [](Geometry& g) { g.spheres[0].radius = 0.2f; }},
      {"vertices[5] is not finite", [](Geometry& g) { g.vertices[5].y = std::nanf(""); }},
      {"vertices[7] is not finite", [](Geometry& g) { g.vertices[7].z = INFINITY; }},
      {"triangles[3] refers to a vertex beyond the 600 vertices", [](Geometry& g) { g.triangles[3].y = 600; }},
  };
  for (const Case& c : cases) {
    Geometry bad = moved;
    c.spoil(bad);
    const std::string message = error_of([&] { accel->refit(bad); });
    EXPECT_NE(message.find(c.expect), std::string::npos) << message;
    EXPECT_NE(message.find("bvh refit"), std::string::npos) << message;
  }
  EXPECT_NE(error_of([&] { accel->refit(moved, {.max_cost_ratio = 0.5}); }).find("policy.max_cost_ratio"),
            std::string::npos);
  const std::vector<Hit> after = run_query(*accel, rays, Query::closest);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    EXPECT_EQ(after[i].prim, before[i].prim) << "ray " << i;
    EXPECT_EQ(after[i].t, before[i].t) << "ray " << i;
  }
  std::unique_ptr<Accel> owned = make_accel(device, "bvh", built);
  EXPECT_NE(error_of([&] { refit_or_rebuild(owned, "grid", moved); }).find("the structure is a bvh"),
            std::string::npos);
}

TEST(Refit, OtherStructuresAreRefusedNamingThemAndRebuilt) {
  const Device& device = test_device();
  const Geometry built = random_soup(300, 8);
  const Geometry moved = sine_deformed(built, 0.05f, 1.0f);
  const Ray ray = random_rays(moved, 1, 2)[0];
  for (const std::string& name : accel_names()) {
    const bool family = name == "bvh" || name == "bvh-ploc" || name == "bvh-packet";
    std::unique_ptr<Accel> accel = make_accel(device, name, built);
    EXPECT_EQ(accel->supports_refit(), family) << name;
    if (family) continue;
    const std::string message = error_of([&] { accel->refit(moved); });
    EXPECT_NE(message.find("structure " + name + " does not support refit"), std::string::npos) << message;
    EXPECT_NE(message.find("supported: bvh, bvh-ploc, bvh-packet"), std::string::npos) << message;
    const RefitStats stats = refit_or_rebuild(accel, name, moved);
    EXPECT_TRUE(stats.rebuilt) << name;
    EXPECT_EQ(accel->name(), name);
    const Hit hit = run_query(*accel, {ray}, Query::closest)[0];
    EXPECT_EQ(judge(moved, ray, hit, Query::closest), "") << name;
  }
}

// A refit holds the structure's lock until its update has run: a query on
// another thread sees the vertices before it or after it, never a mix.
TEST(Refit, QueriesOnOtherThreadsSeeOneStateOrTheOther) {
  const Device& device = test_device();
  const Geometry a = random_soup(2000, 31, 0.05f);
  const Geometry b = sine_deformed(a, 0.1f, 2.0f);
  const std::vector<Ray> rays = random_rays(a, 400, 32);
  std::vector<Hit> expected[2];
  for (int k = 0; k < 2; ++k) expected[k] = run_query(*make_accel(device, "brute", k ? b : a), rays, Query::closest);
  const auto matches = [&](const std::vector<Hit>& hits, int k) {
    for (std::size_t i = 0; i < rays.size(); ++i)
      if (hits[i].prim != expected[k][i].prim || (hits[i].prim >= 0 && hits[i].t != expected[k][i].t)) return false;
    return true;
  };
  ASSERT_FALSE(matches(expected[0], 1)) << "the two states must answer differently";
  auto accel = make_accel(device, "bvh", a);
  std::atomic<bool> done{false};
  std::atomic<std::size_t> calls{0};
  std::size_t mixed = 0;
  std::thread queries([&] {
    while (!done.load()) {
      const std::vector<Hit> hits = accel->intersect(rays);
      if (!matches(hits, 0) && !matches(hits, 1)) ++mixed;
      ++calls;
    }
  });
  // Refits in pairs (to b, back to a) from the first query on, at least 10
  // pairs and until the queries have made 20 calls beside them.
  while (calls.load() == 0) std::this_thread::yield();
  for (int pair = 0; pair < 10 || calls.load() < 20; ++pair) {
    EXPECT_FALSE(accel->refit(b).refused);
    EXPECT_FALSE(accel->refit(a).refused);
  }
  done = true;
  queries.join();
  EXPECT_EQ(mixed, 0u) << "of " << calls.load() << " calls";
  EXPECT_TRUE(matches(accel->intersect(rays), 0));
}

// The reported cost: 1x the build's for the built vertices and for a
// uniformly scaled copy (a cost of box areas relative to the root's), and
// growing with the amplitude of a deformation that moves neighbours
// apart; past the policy's ratio the refit asks for a rebuild.
TEST(Refit, SahCostGrowsWithTheDeformation) {
  const Device& device = test_device();
  const Geometry built = random_soup(4000, 21, 0.03f);
  for (const std::string& name : kRefittable) {
    SCOPED_TRACE(name);
    auto accel = make_accel(device, name, built);
    // A presplit build's leaf boxes were clipped to parts of triangles; a
    // refit boxes whole triangles: no lower.
    const bool presplit = name.find("presplit") != std::string::npos;
    const RefitStats same = accel->refit(built);
    EXPECT_GT(same.build_cost, 1.0);
    if (presplit)
      EXPECT_GE(same.cost_ratio(), 1.0 - 1e-5);
    else
      EXPECT_NEAR(same.cost_ratio(), 1.0, 1e-5);
    Geometry scaled = built;
    for (glm::vec3& v : scaled.vertices) v = 4.0f * v + glm::vec3(1.0f, -2.0f, 3.0f);
    EXPECT_NEAR(accel->refit(scaled).cost_ratio(), same.cost_ratio(), 1e-4);
    double previous = same.cost_ratio();
    for (float amplitude : {0.01f, 0.03f, 0.1f, 0.3f}) {
      const RefitStats stats = accel->refit(sine_deformed(built, amplitude, 8.0f), {.max_cost_ratio = 2.0});
      EXPECT_GT(stats.cost_ratio(), previous * 1.02) << "amplitude " << amplitude;
      EXPECT_EQ(stats.needs_rebuild, stats.cost_ratio() > 2.0) << "amplitude " << amplitude;
      EXPECT_FALSE(stats.refused);
      previous = stats.cost_ratio();
    }
    EXPECT_GT(previous, 2.0) << "the largest deformation should pass the policy's ratio";
  }
}

}  // namespace
}  // namespace rtcl::test
