// Scene::update_vertices then Scene::commit (src/rtcl/scene/mesh_refit.*):
// the commit refits the mesh's tree (counted by CommitStats) and every
// answer, closest and any hit with instance ids, is judged by the
// double-precision reference over the moved vertices, on the single-level
// path and through transformed instances (also when only one of several
// meshes moved: its nodes and blocks are written into a copy of the
// previous commit's); a triangle that gains its area, a cost past the
// policy or a mesh without a refit policy rebuilds; a failed commit leaves
// the scene as it was.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/scene.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/error_of.hpp"
#include "support/everywhere.hpp"
#include "support/fixtures.hpp"
#include "support/instances.hpp"
#include "support/reference.hpp"
#include "support/scoped_env.hpp"

namespace rtcl::test {
namespace {

using everywhere::expect_at_level;

std::vector<float> xyz_of(const Geometry& g) {
  std::vector<float> xyz;
  xyz.reserve(3 * g.vertices.size());
  for (const glm::vec3& v : g.vertices) xyz.insert(xyz.end(), {v.x, v.y, v.z});
  return xyz;
}

// The world of placed meshes as one flat geometry (instance k's triangle p
// is triangle first[k] + p), transformed in double and rounded once.
struct FlatWorld {
  Geometry geometry;
  std::vector<std::uint32_t> first;
};
FlatWorld world_of(const std::vector<const Geometry*>& meshes, const std::vector<Transform>& transforms) {
  FlatWorld w;
  w.geometry.source = "placed meshes";
  for (std::size_t k = 0; k < meshes.size(); ++k) {
    const auto base = static_cast<std::uint32_t>(w.geometry.vertices.size());
    w.first.push_back(static_cast<std::uint32_t>(w.geometry.triangles.size()));
    for (const glm::vec3& v : meshes[k]->vertices) w.geometry.vertices.emplace_back(apply(transforms[k], glm::dvec3(v)));
    for (const glm::uvec3& t : meshes[k]->triangles) w.geometry.triangles.push_back(t + glm::uvec3(base));
  }
  return w;
}

// The rays and the double-precision reference's closest hits in a world.
struct Judged {
  std::vector<Ray> rays;
  std::vector<Hit> references;
};
Judged judged(const FlatWorld& world, std::vector<Ray> rays) {
  std::vector<Hit> references = reference_closest_all(world.geometry, rays);
  return {std::move(rays), std::move(references)};
}

// The scene's closest and any hits with instance ids (user ids = indices
// into the world's instances), mapped into the world and judged; ids of
// misses must be kNoInstance.
void expect_scene_answers(const Scene& scene, const FlatWorld& world, const Judged& judged, const std::string& what) {
  const std::vector<Ray>& rays = judged.rays;
  const std::vector<Hit>& references = judged.references;
  std::size_t hits_seen = 0;
  for (Query query : {Query::closest, Query::any}) {
    std::vector<Hit> hits(rays.size());
    std::vector<std::uint32_t> ids(rays.size());
    scene.trace(query, rays, hits, ids);
    std::vector<Hit> mapped = hits;
    std::size_t bad_ids = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      if (hits[i].prim < 0) {
        bad_ids += ids[i] != kNoInstance;
        continue;
      }
      ++hits_seen;
      if (ids[i] >= world.first.size()) {
        ++bad_ids;
        mapped[i].prim = -1;
        continue;
      }
      mapped[i].prim = static_cast<std::int32_t>(world.first[ids[i]] + static_cast<std::uint32_t>(hits[i].prim));
    }
    const std::string label = what + (query == Query::closest ? " closest" : " any");
    EXPECT_EQ(bad_ids, 0u) << label;
    expect_at_level(scene.precision(), false, label, [&] {
      std::size_t failures = 0;
      const std::vector<std::string> report =
          judge_all(world.geometry, rays, mapped, query, references, &failures, 3);
      EXPECT_EQ(failures, 0u) << label << ": " << (report.empty() ? "" : report.front());
    });
    if (query == Query::any) {
      std::vector<std::uint8_t> expected(rays.size());
      for (std::size_t i = 0; i < rays.size(); ++i) expected[i] = hits[i].prim >= 0;
      EXPECT_EQ(scene.occluded(rays), expected) << label;
    }
  }
  EXPECT_GT(hits_seen, rays.size() / 5) << what;
}

TEST(SceneRefit, OneMeshIsRefittedAndAnswersForItsNewVertices) {
  const Geometry built = bunny();
  const Geometry moved = sine_deformed(built, 0.02f, 1.5f), again = sine_deformed(built, -0.03f, 1.0f);
  const FlatWorld moved_world = world_of({&moved}, {Transform::identity()});
  const FlatWorld again_world = world_of({&again}, {Transform::identity()});
  const Judged moved_rays = judged(moved_world, random_rays(moved, 1200, 31));
  const Judged again_rays = judged(again_world, random_rays(again, 600, 32));
  for (Precision level : test_precisions()) {
    Scene scene(test_device(), {level});
    const MeshId mesh = scene.add_mesh(built);
    scene.add_instance({mesh, Transform::identity(), std::nullopt, 0u});
    scene.commit();
    ASSERT_TRUE(scene.stats().single_level);
    scene.update_vertices(mesh, xyz_of(moved));
    const CommitStats refit = scene.commit();
    EXPECT_EQ(refit.bottom_levels_refitted, 1u);
    EXPECT_EQ(refit.bottom_levels_built, 0u);
    EXPECT_FALSE(refit.top_level_built);
    EXPECT_TRUE(scene.stats().single_level);
    const std::string what = "single level " + std::string(precision_name(level));
    expect_scene_answers(scene, moved_world, moved_rays, what);
    // A second refit starts from the first's tree; the totals add up.
    scene.update_vertices(mesh, xyz_of(again));
    EXPECT_EQ(scene.commit().bottom_levels_refitted, 1u);
    expect_scene_answers(scene, again_world, again_rays, what + ", refitted twice");
    const SceneStats stats = scene.stats();
    EXPECT_EQ(stats.bottom_levels_built, 1u);
    EXPECT_EQ(stats.bottom_levels_refitted, 2u);
  }
}

// Two meshes placed by rotations, mirroring and non-uniform scale; one
// moves, then the other: each commit refits the one that moved (its ranges
// written into a copy of the previous bottom levels, the other's kept) and
// rebuilds the top level over the new boxes.
TEST(SceneRefit, InstancesOfRefittedMeshesAnswerForTheirNewVertices) {
  Geometry a = random_soup(2500, 41, 0.06f);
  a.source = "soup a";
  Geometry b = random_soup(1800, 42, 0.08f);
  b.source = "soup b";
  const std::vector<Transform> transforms = {
      Transform::rotate(37, 1, 2, 3),
      Transform::translate(3, 0, 0) * Transform::scale(2, 0.5f, 1),
      Transform::translate(0, 3, 0) * Transform::scale(-1, 1, 1),
      Transform::translate(3, 3, 0) * Transform::rotate(-70, 0, 1, 1) * Transform::scale(0.25f, 1.5f, -1),
      Transform::translate(-3, 0.5f, 0),
  };
  const std::vector<int> of_b = {0, 1, 0, 1, 1};  // which mesh each instance places
  const Geometry a_moved = sine_deformed(a, 0.04f, 1.5f), b_moved = sine_deformed(b, -0.05f, 2.0f);
  const auto world = [&](const Geometry& ga, const Geometry& gb) {
    std::vector<const Geometry*> meshes;
    for (int m : of_b) meshes.push_back(m ? &gb : &ga);
    return world_of(meshes, transforms);
  };
  std::vector<Ray> rays;
  for (std::uint32_t k = 0; k < transforms.size(); ++k) {
    const FlatInstances one = flatten_instances(of_b[k] ? b_moved : a_moved, {transforms[k]});
    const std::vector<Ray> some = random_rays(one.geometry, 400, 50 + k);
    rays.insert(rays.end(), some.begin(), some.end());
  }
  const FlatWorld b_moves = world(a, b_moved), both_move = world(a_moved, b_moved), neither = world(a, b);
  const Judged b_moves_rays = judged(b_moves, rays), both_move_rays = judged(both_move, rays),
               neither_rays = judged(neither, rays);
  for (Precision level : test_precisions()) {
    Scene scene(test_device(), {level});
    const MeshId ma = scene.add_mesh(a), mb = scene.add_mesh(b);
    for (std::uint32_t k = 0; k < transforms.size(); ++k)
      scene.add_instance({of_b[k] ? mb : ma, transforms[k], std::nullopt, k});
    scene.commit();
    const std::string at = " " + std::string(precision_name(level));

    scene.update_vertices(mb, xyz_of(b_moved));  // the second mesh: its nodes and blocks start past a's
    CommitStats stats = scene.commit();
    EXPECT_EQ(stats.bottom_levels_refitted, 1u);
    EXPECT_EQ(stats.bottom_levels_built, 0u);
    EXPECT_TRUE(stats.top_level_built);
    expect_scene_answers(scene, b_moves, b_moves_rays, "b moved" + at);

    scene.update_vertices(ma, xyz_of(a_moved));
    stats = scene.commit();
    EXPECT_EQ(stats.bottom_levels_refitted, 1u);
    EXPECT_EQ(stats.bottom_levels_built, 0u);
    expect_scene_answers(scene, both_move, both_move_rays, "a and b moved" + at);

    // Both back where they were built, in one commit.
    scene.update_vertices(ma, xyz_of(a));
    scene.update_vertices(mb, xyz_of(b));
    stats = scene.commit();
    EXPECT_EQ(stats.bottom_levels_refitted, 2u);
    expect_scene_answers(scene, neither, neither_rays, "both back" + at);
    EXPECT_EQ(scene.stats().bottom_levels_refitted, 4u);
    EXPECT_EQ(scene.stats().bottom_levels_built, 2u);
  }
}

// The refit has no place for a triangle that was skipped at the build: the
// commit rebuilds, on either path, and the triangle is hit.
TEST(SceneRefit, ATriangleThatGainsItsAreaIsRebuilt) {
  const Geometry built = with_a_degenerate_triangle();
  Geometry moved = built;
  moved.vertices[5] = {3, 1, 0};  // triangle 2 now spans (2,0)-(3,1)-(4,0)
  const Ray down = make_ray({3.0f, 0.4f, 1.0f}, {0.0f, 0.0f, -1.0f});  // meets triangle 2 only
  ASSERT_EQ(reference_closest(moved, down).prim, 2);
  const std::vector<Ray> rays = {down};
  for (bool two_levels : {false, true}) {
    SCOPED_TRACE(two_levels ? "two levels" : "single level");
    Scene scene(test_device());
    const MeshId mesh = scene.add_mesh(built);
    scene.add_instance(mesh);
    if (two_levels) scene.add_instance(mesh, Transform::translate(0, 0, -10));
    scene.commit();
    EXPECT_EQ(scene.intersect(rays)[0].prim, -1);
    scene.update_vertices(mesh, xyz_of(moved));
    const CommitStats stats = scene.commit();
    EXPECT_EQ(stats.bottom_levels_built, 1u);
    EXPECT_EQ(stats.bottom_levels_refitted, 0u);
    std::vector<std::uint32_t> ids(1);
    const Hit hit = scene.intersect(rays, ids)[0];
    EXPECT_EQ(hit.prim, 2);
    EXPECT_EQ(ids[0], 0u);
  }
}

// Vertices scattered at random over the same triangles make a tree whose
// refitted cost passes the default policy: rebuilt. With max_cost_ratio
// +inf the same update is refitted; without a refit policy every update
// rebuilds. Either way the answers are the moved mesh's.
TEST(SceneRefit, ThePolicyDecidesBetweenRefitAndRebuild) {
  Geometry built = random_soup(2000, 61, 0.05f);
  built.source = "soup";
  Geometry scattered = built;
  std::mt19937 rng(62);
  std::shuffle(scattered.vertices.begin(), scattered.vertices.end(), rng);
  scattered.source = "soup, vertices shuffled";
  const Geometry nudged = sine_deformed(built, 0.01f, 1.0f);
  struct Case {
    std::optional<RefitPolicy> policy;
    const Geometry* moved;
    std::size_t refitted;
  };
  const std::vector<Case> cases = {{RefitPolicy{}, &scattered, 0},
                                   {RefitPolicy{.max_cost_ratio = INFINITY}, &scattered, 1},
                                   {RefitPolicy{}, &nudged, 1},
                                   {std::nullopt, &nudged, 0}};
  for (const Case& c : cases) {
    const std::string what = c.moved->source + (c.policy ? ", max_cost_ratio " + std::to_string(c.policy->max_cost_ratio)
                                                         : ", no refit policy");
    SCOPED_TRACE(what);
    Scene scene(test_device());
    MeshOptions options;
    options.refit = c.policy;
    const MeshId mesh = scene.add_mesh(built, options);
    scene.add_instance({mesh, Transform::identity(), std::nullopt, 0u});
    scene.add_instance({mesh, Transform::translate(5, 0, 0), std::nullopt, 1u});
    scene.commit();
    scene.update_vertices(mesh, xyz_of(*c.moved));
    const CommitStats stats = scene.commit();
    EXPECT_EQ(stats.bottom_levels_refitted, c.refitted);
    EXPECT_EQ(stats.bottom_levels_built, 1 - c.refitted);
    const FlatWorld placed = world_of({c.moved, c.moved}, {Transform::identity(), Transform::translate(5, 0, 0)});
    expect_scene_answers(scene, placed, judged(placed, random_rays(*c.moved, 800, 63)), what);
  }
  Scene scene(test_device());
  MeshOptions bad;
  bad.refit = RefitPolicy{.max_cost_ratio = 0.5};
  const std::string e = error_of([&] { scene.add_mesh(built, bad); });
  EXPECT_NE(e.find("Scene::add_mesh refit.max_cost_ratio"), std::string::npos) << e;
  EXPECT_NE(e.find(">= 1"), std::string::npos) << e;
  EXPECT_EQ(scene.stats().meshes, 0u);
}

// A commit whose refit cannot get its buffers (the device's memory,
// lowered for the test, holds the bottom levels once, not twice) leaves the
// last commit answering, its stats and the edit pending; a wrong vertex
// count is refused naming the mesh, changing nothing.
TEST(SceneRefit, AFailedRefitCommitLeavesTheSceneAsItWas) {
  ScopedEnv limit("RTCL_MAX_GLOBAL_BYTES", std::to_string(4u << 20));
  Device device = Device::open();
  Geometry big = random_soup(60000, 71, 0.01f);  // about 2.4 MB of blocks and nodes
  big.source = "big soup";
  for (bool two_levels : {false, true}) {
    SCOPED_TRACE(two_levels ? "two levels" : "single level");
    Scene scene(device);
    const MeshId mesh = scene.add_mesh(big);
    scene.add_instance(mesh);
    if (two_levels) scene.add_instance(mesh, Transform::translate(0, 0, 5));
    scene.commit();
    const std::vector<Ray> rays = random_rays(big, 500, 72);
    const std::vector<Hit> before = scene.intersect(rays);
    const SceneStats stats_before = scene.stats();

    std::string e = error_of([&] { scene.update_vertices(mesh, std::vector<float>(30, 0.0f)); });
    EXPECT_NE(e.find("Scene::update_vertices mesh 0 (big soup)"), std::string::npos) << e;
    EXPECT_NE(e.find("30 coordinates"), std::string::npos) << e;
    const CommitStats nothing = scene.commit();
    EXPECT_EQ(nothing.bottom_levels_built + nothing.bottom_levels_refitted, 0u);

    scene.update_vertices(mesh, xyz_of(sine_deformed(big, 0.02f, 1.0f)));
    for (int attempt = 0; attempt < 2; ++attempt) {  // the edit stays pending
      e = error_of([&] { scene.commit(); });
      EXPECT_NE(e.find("Scene::commit"), std::string::npos) << e;
      EXPECT_TRUE(same_bits(scene.intersect(rays), before));
      EXPECT_EQ(scene.stats().bottom_levels_refitted, stats_before.bottom_levels_refitted);
      EXPECT_EQ(scene.stats().bottom_levels_built, stats_before.bottom_levels_built);
      EXPECT_EQ(scene.stats().device_bytes, stats_before.device_bytes);
    }
  }
}

}  // namespace
}  // namespace rtcl::test
