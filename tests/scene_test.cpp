// rtcl::Scene (src/rtcl/scene/scene.cpp): what a commit builds, the
// single-level path, ids, bad input and the strong guarantee, the buffer
// path. Answers through transformed instances are checked against
// references in two_level_test.cpp.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/scene.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/error_of.hpp"
#include "support/fixtures.hpp"
#include "support/scoped_env.hpp"

namespace rtcl::test {
namespace {


// Rays towards the geometry from around it, ending at `tmax`.
std::vector<Ray> rays_at(const Geometry& g, std::size_t count, std::uint32_t seed, float tmax) {
  std::vector<Ray> rays = random_rays(g, count, seed);
  for (Ray& r : rays) r.tmax = tmax;
  return rays;
}

TEST(Scene, OneIdentityInstanceIsTheMeshsOwnStructure) {
  const Geometry g = bunny();
  const std::vector<Ray> rays = random_rays(g, 4000, 11);
  for (Precision level : test_precisions()) {
    AccelConfig config;
    config.precision = level;
    auto flat = make_accel(test_device(), "bvh", g, config);
    Scene scene(test_device(), {level});
    scene.add_instance(scene.add_mesh(g));
    scene.commit();
    EXPECT_TRUE(scene.stats().single_level);
    std::vector<std::uint32_t> ids(rays.size());
    std::vector<Hit> hits = scene.intersect(rays, ids);
    EXPECT_TRUE(same_bits(hits, flat->intersect(rays))) << precision_name(level);
    EXPECT_EQ(scene.occluded(rays), flat->occluded(rays)) << precision_name(level);
    for (std::size_t i = 0; i < rays.size(); ++i)
      ASSERT_EQ(ids[i], hits[i].prim >= 0 ? 0u : kNoInstance) << "ray " << i;
  }
}

// Two instances make the scene two-level: the identity one answers as the
// flat structure does, bit for bit (the same object ray, the same bottom
// level, the same triangle tests), at every level.
TEST(Scene, IdentityInstanceOfATwoLevelSceneAnswersAsTheFlatStructure) {
  const Geometry g = bunny();
  const float extent = glm::length(g.bounds().extent());
  // Rays from around the bunny, cut before they could reach the far copy.
  const std::vector<Ray> rays = rays_at(g, 4000, 12, 4.0f);
  for (Precision level : test_precisions()) {
    AccelConfig config;
    config.precision = level;
    auto flat = make_accel(test_device(), "bvh", g, config);
    Scene scene(test_device(), {level});
    MeshId mesh = scene.add_mesh(g);
    scene.add_instance({mesh, Transform::identity(), std::nullopt, 5u});
    scene.add_instance({mesh, Transform::translate(100.0f * extent, 0, 0), std::nullopt, 6u});
    scene.commit();
    ASSERT_FALSE(scene.stats().single_level);
    std::vector<std::uint32_t> ids(rays.size());
    const std::vector<Hit> hits = scene.intersect(rays, ids);
    const std::vector<Hit> expected = flat->intersect(rays);
    ASSERT_TRUE(same_bits(hits, expected)) << precision_name(level);
    std::size_t hit_count = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      ASSERT_EQ(ids[i], hits[i].prim >= 0 ? 5u : kNoInstance) << "ray " << i;
      hit_count += hits[i].prim >= 0;
    }
    EXPECT_GT(hit_count, rays.size() / 10);
    EXPECT_EQ(scene.occluded(rays), flat->occluded(rays)) << precision_name(level);
  }
}

TEST(Scene, CommitBuildsOnlyWhatChanged) {
  Geometry a = random_soup(500, 1), b = random_soup(300, 2);
  Scene scene(test_device());
  MeshId ma = scene.add_mesh(a);
  MeshId mb = scene.add_mesh(b);
  InstanceId i0 = scene.add_instance(ma, Transform::translate(0, 0, 0));
  for (int k = 1; k <= 20; ++k) scene.add_instance(mb, Transform::translate(2.0f * k, 0, 0));
  CommitStats first = scene.commit();
  EXPECT_EQ(first.bottom_levels_built, 2u);
  EXPECT_TRUE(first.top_level_built);

  CommitStats nothing = scene.commit();
  EXPECT_EQ(nothing.bottom_levels_built, 0u);
  EXPECT_FALSE(nothing.top_level_built);

  scene.set_transform(i0, Transform::translate(0, 3, 0));
  CommitStats moved = scene.commit();
  EXPECT_EQ(moved.bottom_levels_built, 0u);
  EXPECT_TRUE(moved.top_level_built);

  std::vector<float> xyz;
  for (const glm::vec3& v : a.vertices) xyz.insert(xyz.end(), {v.x, v.y, v.z + 0.5f});
  scene.update_vertices(ma, xyz);
  CommitStats updated = scene.commit();  // moved as a whole: its tree is refitted
  EXPECT_EQ(updated.bottom_levels_built, 0u);
  EXPECT_EQ(updated.bottom_levels_refitted, 1u);
  EXPECT_TRUE(updated.top_level_built);

  SceneStats s = scene.stats();
  EXPECT_EQ(s.meshes, 2u);
  EXPECT_EQ(s.instances, 21u);
  EXPECT_EQ(s.bottom_levels_built, 2u);
  EXPECT_EQ(s.bottom_levels_refitted, 1u);
  EXPECT_EQ(s.top_levels_built, 3u);
}

// Many instances of one mesh build one bottom level, and each instance's
// hits report its user id and the mesh's own primitive ids.
TEST(Scene, ManyInstancesOfOneMeshBuildOneBottomLevel) {
  const float xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::uint32_t tri[] = {0, 1, 2};
  Scene scene(test_device());
  MeshId mesh = scene.add_mesh(Geometry::from_arrays(xyz, 3, tri, 1, "triangle"));
  std::vector<Ray> rays;
  for (std::uint32_t k = 0; k < 1000; ++k) {
    scene.add_instance({mesh, Transform::translate(3.0f * static_cast<float>(k), 0, 0), std::nullopt, 1000 + k});
    rays.push_back({3.0f * static_cast<float>(k) + 0.25f, 0.25f, 1.0f, 0, 0, -1, 0, kInf});
  }
  CommitStats built = scene.commit();
  EXPECT_EQ(built.bottom_levels_built, 1u);
  std::vector<std::uint32_t> ids(rays.size());
  std::vector<Hit> hits = scene.intersect(rays, ids);
  for (std::uint32_t k = 0; k < rays.size(); ++k) {
    ASSERT_EQ(hits[k].prim, 0) << "ray " << k;
    ASSERT_EQ(hits[k].t, 1.0f) << "ray " << k;
    ASSERT_EQ(ids[k], 1000 + k) << "ray " << k;
  }
}

TEST(Scene, RemovedInstancesAndUncommittedScenesAreNotHit) {
  const float xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::uint32_t tri[] = {0, 1, 2};
  Scene scene(test_device());
  const std::vector<Ray> rays = {{0.25f, 0.25f, 1.0f, 0, 0, -1, 0, kInf}, {5.25f, 0.25f, 1.0f, 0, 0, -1, 0, kInf}};
  std::vector<std::uint32_t> ids(2, 0);
  std::vector<Hit> hits = scene.intersect(rays, ids);
  EXPECT_TRUE(hits[0].prim < 0 && hits[1].prim < 0 && ids[0] == kNoInstance && ids[1] == kNoInstance);

  MeshId mesh = scene.add_mesh(Geometry::from_arrays(xyz, 3, tri, 1, "triangle"));
  InstanceId near = scene.add_instance(mesh);
  InstanceId far = scene.add_instance(mesh, Transform::translate(5, 0, 0));
  hits = scene.intersect(rays);  // not committed yet
  EXPECT_TRUE(hits[0].prim < 0 && hits[1].prim < 0);
  scene.commit();
  hits = scene.intersect(rays, ids);
  EXPECT_TRUE(hits[0].prim == 0 && hits[1].prim == 0 && ids[0] == near.value && ids[1] == far.value);
  scene.remove_instance(near);
  hits = scene.intersect(rays, ids);  // the removal is pending
  EXPECT_EQ(ids[0], near.value);
  scene.commit();
  hits = scene.intersect(rays, ids);
  EXPECT_TRUE(hits[0].prim < 0 && ids[0] == kNoInstance && hits[1].prim == 0 && ids[1] == far.value);
  scene.remove_instance(far);
  scene.remove_mesh(mesh);
  scene.commit();
  hits = scene.intersect(rays, ids);
  EXPECT_TRUE(hits[0].prim < 0 && hits[1].prim < 0 && ids[1] == kNoInstance);
  EXPECT_EQ(scene.stats().meshes, 0u);
}

// Every bad call: one Error naming the call, the mesh or instance and the
// problem; the scene as before (the next commit builds nothing, the
// answers stay).
TEST(Scene, BadInputIsRefusedAndChangesNothing) {
  const float xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::uint32_t tri[] = {0, 1, 2};
  Scene scene(test_device());
  MeshId mesh = scene.add_mesh(Geometry::from_arrays(xyz, 3, tri, 1, "triangle"));
  InstanceId inst = scene.add_instance(mesh, Transform::translate(1, 0, 0));
  scene.add_instance(mesh, Transform::translate(5, 0, 0));
  scene.commit();
  const std::vector<Ray> rays = {{1.25f, 0.25f, 1.0f, 0, 0, -1, 0, kInf}, {5.25f, 0.25f, 1.0f, 0, 0, -1, 0, kInf}};
  const std::vector<Hit> before = scene.intersect(rays);
  const SceneStats stats_before = scene.stats();

  const Transform flat = Transform::scale(1, 1, 0);
  Transform nan = Transform::identity();
  nan.m[1][3] = std::numeric_limits<float>::quiet_NaN();
  Transform dependent = Transform::identity();
  dependent.m[2] = {1.0f, 1.0f, 1e-9f, 0.0f};
  dependent.m[1] = {1.0f, 1.0f, 0.0f, 0.0f};
  MeshId missing{77};
  struct Case {
    std::function<void()> call;
    std::vector<std::string> words;
  };
  std::vector<float> short_xyz(6, 0.0f), nan_xyz(9, 0.0f);
  nan_xyz[4] = std::numeric_limits<float>::quiet_NaN();
  const std::vector<Case> cases = {
      {[&] { scene.add_instance(mesh, flat); }, {"Scene::add_instance", "mesh 0", "singular"}},
      {[&] { scene.add_instance(mesh, dependent); }, {"Scene::add_instance", "singular"}},
      {[&] { scene.add_instance(mesh, nan); }, {"Scene::add_instance", "[1][3]", "finite"}},
      {[&] { scene.set_transform(inst, flat); }, {"Scene::set_transform instance 0 (mesh 0)", "singular"}},
      {[&] { scene.add_instance(missing); }, {"mesh 77", "does not exist"}},
      {[&] { scene.set_instance(inst, {missing, Transform::identity(), {}, {}}); }, {"mesh 77", "does not exist"}},
      {[&] { scene.set_transform(InstanceId{99}, Transform::identity()); },
       {"Scene::set_transform", "instance 99", "does not exist"}},
      {[&] { scene.instance(InstanceId{99}); }, {"Scene::instance", "instance 99", "does not exist"}},
      {[&] { scene.remove_instance(InstanceId{99}); }, {"Scene::remove_instance", "instance 99"}},
      {[&] { scene.add_instance({mesh, Transform::identity(), std::nullopt, kNoInstance}); }, {"user_id", "kNoInstance"}},
      {[&] { scene.add_instance({mesh, Transform::identity(), Transform::rotate(180, 0, 0, 1), {}}); },
       {"Scene::add_instance", "blend", "singular"}},
      {[&] { scene.add_instance({mesh, Transform::identity(), flat, {}}); }, {"shutter close", "singular"}},
      {[&] { scene.update_vertices(mesh, short_xyz); }, {"Scene::update_vertices mesh 0 (triangle)", "6 coordinates", "3 vertices"}},
      {[&] { scene.update_vertices(mesh, nan_xyz); }, {"Scene::update_vertices mesh 0 (triangle)", "NaN"}},
      {[&] { scene.update_vertices(missing, short_xyz); }, {"Scene::update_vertices", "mesh 77"}},
      {[&] { scene.remove_mesh(mesh); }, {"Scene::remove_mesh mesh 0 (triangle)", "2 instance(s)", "0, 1"}},
      {[&] { scene.add_mesh(Geometry::from_arrays(xyz, 3, tri, 1), {"grid", {}}); },
       {"Scene::add_mesh structure \"grid\"", "bottom level", "bvh, bvh-ploc, bvh-packet"}},
      {[&] { scene.add_mesh(Geometry::from_arrays(xyz, 3, tri, 1), {"bvh:bin_count=0", {}}); }, {"bin_count"}},
      {[&] { scene.add_mesh(Geometry{}); }, {"Scene::add_mesh", "empty scene"}},
  };
  for (const Case& c : cases) {
    std::string e = error_of(c.call);
    ASSERT_FALSE(e.empty()) << "no error for the case expecting: " << c.words.front();
    for (const std::string& word : c.words) EXPECT_NE(e.find(word), std::string::npos) << e << "\n  lacks: " << word;
    CommitStats nothing = scene.commit();
    EXPECT_EQ(nothing.bottom_levels_built, 0u) << e;
    EXPECT_FALSE(nothing.top_level_built) << e;
    EXPECT_TRUE(same_bits(scene.intersect(rays), before)) << e;
    EXPECT_EQ(scene.stats().instances, stats_before.instances) << e;
    EXPECT_EQ(scene.instance(inst).transform, Transform::translate(1, 0, 0)) << e;
  }
}

// A commit that fails (here: the device's memory, lowered for the test,
// cannot hold the new mesh) leaves the last commit answering and the edits
// pending; once they are undone the next commit succeeds.
TEST(Scene, AFailedCommitLeavesTheSceneAsItWas) {
  ScopedEnv limit("RTCL_MAX_GLOBAL_BYTES", std::to_string(4u << 20));
  Device device = Device::open();
  const float xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::uint32_t tri[] = {0, 1, 2};
  Scene scene(device);
  MeshId small = scene.add_mesh(Geometry::from_arrays(xyz, 3, tri, 1, "triangle"));
  scene.add_instance(small, Transform::translate(1, 0, 0));
  scene.add_instance(small, Transform::translate(5, 0, 0));
  scene.commit();
  const std::vector<Ray> rays = {{1.25f, 0.25f, 1.0f, 0, 0, -1, 0, kInf}, {5.25f, 0.25f, 1.0f, 0, 0, -1, 0, kInf}};
  const std::vector<Hit> before = scene.intersect(rays);
  const SceneStats stats_before = scene.stats();

  MeshId big = scene.add_mesh(random_soup(150000, 5));  // about 6 MB of blocks and nodes
  InstanceId extra = scene.add_instance(big, Transform::translate(0, 10, 0));
  std::string e = error_of([&] { scene.commit(); });
  EXPECT_NE(e.find("Scene::commit: the scene's bottom levels' "), std::string::npos) << e;
  EXPECT_TRUE(same_bits(scene.intersect(rays), before));
  EXPECT_EQ(scene.stats().bottom_levels_built, stats_before.bottom_levels_built);
  EXPECT_EQ(scene.stats().instances, 2u);

  scene.remove_instance(extra);
  scene.remove_mesh(big);
  CommitStats after = scene.commit();
  EXPECT_EQ(after.bottom_levels_built, 0u);
  EXPECT_TRUE(same_bits(scene.intersect(rays), before));
}

// The buffer path answers as the host arrays do, with instance ids and
// per-ray times read through a stride.
TEST(Scene, BuffersAnswerAsHostArrays) {
  const Geometry g = random_soup(2000, 7);
  Scene scene(test_device());
  MeshId mesh = scene.add_mesh(g);
  scene.add_instance(mesh, Transform::rotate(30, 0, 1, 0));
  scene.add_instance({mesh, Transform::translate(0, 1.5f, 0), Transform::translate(0.5f, 1.5f, 0), 9u});
  scene.commit();
  std::vector<Ray> rays = random_rays(random_soup(10, 8, 0.05f, 2.5f, glm::vec3(-0.5f)), 3000, 9);
  std::vector<float> times(rays.size());
  for (std::size_t i = 0; i < times.size(); ++i) times[i] = static_cast<float>(i % 5) / 4.0f;
  std::vector<std::uint32_t> ids(rays.size());
  const std::vector<Hit> expected = scene.intersect(rays, ids, times);

  const Device& d = test_device();
  cl::Buffer ray_buffer = d.upload(rays.data(), rays.size() * sizeof(Ray), "rays");
  cl::Buffer hit_buffer = d.allocate(rays.size() * sizeof(Hit), "hits");
  SceneBuffers extra;
  extra.instance_ids = d.allocate(rays.size() * sizeof(cl_uint), "ids");
  std::vector<float> strided(2 * times.size() + 1, -7.0f);  // times at odd indices
  for (std::size_t i = 0; i < times.size(); ++i) strided[2 * i + 1] = times[i];
  extra.times = d.upload(strided.data(), strided.size() * sizeof(float), "times");
  extra.time_stride = 2;
  extra.time_offset = 1;
  scene.trace(Query::closest, ray_buffer, hit_buffer, rays.size(), extra).wait();
  std::vector<Hit> hits(rays.size());
  std::vector<std::uint32_t> buffer_ids(rays.size());
  d.queue().enqueueReadBuffer(hit_buffer, CL_TRUE, 0, hits.size() * sizeof(Hit), hits.data());
  d.queue().enqueueReadBuffer(extra.instance_ids, CL_TRUE, 0, ids.size() * sizeof(cl_uint), buffer_ids.data());
  EXPECT_TRUE(same_bits(hits, expected));
  EXPECT_EQ(buffer_ids, ids);
  std::size_t moving_hits = 0;
  for (std::uint32_t id : ids) moving_hits += id == 9u;
  EXPECT_GT(moving_hits, 0u);

  SceneBuffers short_times = extra;
  short_times.times = d.allocate(rays.size() * sizeof(float), "times");
  std::string e = error_of([&] { scene.trace(Query::closest, ray_buffer, hit_buffer, rays.size(), short_times); });
  EXPECT_NE(e.find("times buffer"), std::string::npos) << e;
  std::vector<std::uint32_t> wrong(3);
  e = error_of([&] { scene.intersect(rays, wrong); });
  EXPECT_NE(e.find("instance_ids holds 3 values"), std::string::npos) << e;
}

// Host arrays in many batches (the device's buffers lowered to 997 rays),
// in place and copied, as records and as separate arrays: instance ids
// and times stay with their rays.
TEST(Scene, BatchesKeepIdsAndTimesWithTheirRays) {
  const Geometry g = random_soup(300, 17);  // its blocks fit the lowered buffers
  const auto fill = [&](Scene& scene) {
    MeshId mesh = scene.add_mesh(g);
    scene.add_instance(mesh, Transform::rotate(30, 0, 1, 0));
    scene.add_instance({mesh, Transform::translate(0, 1.5f, 0), Transform::translate(0.5f, 1.5f, 0), 9u});
    scene.commit();
  };
  std::vector<Ray> rays = random_rays(random_soup(10, 8, 0.05f, 2.5f, glm::vec3(-0.5f)), 5000, 19);
  std::vector<float> times(rays.size()), origins, directions;
  for (std::size_t i = 0; i < times.size(); ++i) times[i] = static_cast<float>(i % 7) / 6.0f;
  for (const Ray& r : rays) {
    origins.insert(origins.end(), {r.ox, r.oy, r.oz});
    directions.insert(directions.end(), {r.dx, r.dy, r.dz});
  }
  Scene whole(test_device());
  fill(whole);
  std::vector<std::uint32_t> expected_ids(rays.size());
  const std::vector<Hit> expected = whole.intersect(rays, expected_ids, times);
  ScopedEnv small("RTCL_MAX_ALLOC_BYTES", std::to_string(997 * sizeof(Ray)));
  Device device = Device::open();
  Scene batched(device);
  fill(batched);
  for (const char* mode : {"", "copy"}) {
    ScopedEnv host_arrays("RTCL_HOST_ARRAYS", std::string(mode));
    for (bool records : {true, false}) {
      std::vector<std::uint32_t> ids(rays.size());
      std::vector<Hit> hits = records ? batched.intersect(rays, ids, times)
                                      : batched.intersect(Rays(origins, directions), ids, times);
      EXPECT_TRUE(same_bits(hits, expected)) << "mode '" << mode << "', records " << records;
      EXPECT_EQ(ids, expected_ids) << "mode '" << mode << "', records " << records;
    }
  }
}

// Queries during commits see one commit or the other, never a mix: rays
// each aimed at the one instance that moves between two places.
TEST(Scene, QueriesDuringCommitsSeeWholeCommits) {
  const float xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::uint32_t tri[] = {0, 1, 2};
  Scene scene(test_device());
  MeshId mesh = scene.add_mesh(Geometry::from_arrays(xyz, 3, tri, 1, "triangle"));
  InstanceId moving = scene.add_instance(mesh, Transform::translate(0, 0, 0));
  scene.add_instance(mesh, Transform::translate(0, 0, -10));
  scene.commit();
  const std::vector<Ray> rays(64, Ray{0.25f, 0.25f, 1.0f, 0, 0, -1, 0, kInf});
  std::atomic<bool> stop{false};
  std::atomic<std::size_t> mixed{0}, calls{0};
  std::atomic<int> started{0};
  std::vector<std::thread> readers;
  for (int r = 0; r < 3; ++r)
    readers.emplace_back([&] {
      ++started;
      while (!stop) {
        std::vector<Hit> hits = scene.intersect(rays);
        for (const Hit& h : hits)
          if (h.t != hits[0].t || (h.t != 1.0f && h.t != 3.0f)) ++mixed;
        ++calls;
      }
    });
  // The commits start once every reader runs, and go on until the readers
  // have made a few calls (a loaded machine can hold a new thread back for
  // longer than 40 commits take).
  while (started < 3) std::this_thread::yield();
  for (int k = 0; k < 40 || (calls < 6 && k < 20000); ++k) {
    scene.set_transform(moving, Transform::translate(0, 0, k % 2 ? -2.0f : 0.0f));
    scene.commit();
  }
  stop = true;
  for (std::thread& t : readers) t.join();
  EXPECT_EQ(mixed.load(), 0u);
  EXPECT_GT(calls.load(), 0u);
}

}  // namespace
}  // namespace rtcl::test
