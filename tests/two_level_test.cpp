// Two-level traversal (src/rtcl/scene/two_level.cpp, kernels/accel/
// instances.cl) against references: a pre-transformed flat copy traced by
// the flat BVH, the double-precision judge over that copy, closed meshes
// instanced with rotations, mirroring, non-uniform scale and large
// translations (no leaks at robust and exact), moving instances at fixed
// times, and the top level's build.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/scene.hpp"
#include "rtcl/scene/two_level.hpp"
#include "support/closed_meshes.hpp"
#include "support/everywhere.hpp"
#include "support/fixtures.hpp"
#include "support/instances.hpp"
#include "support/reference.hpp"

namespace rtcl::test {
namespace {

using everywhere::describe;
using everywhere::disagreements_with_brute;
using everywhere::expect_at_level;

constexpr double kFloatUlp = 5.9604644775390625e-8;  // 2^-24

// The condition number of the transform's linear part (Frobenius norms).
double condition(const Transform& t) {
  const glm::dmat3 a = linear_part(t), inv = glm::inverse(a);
  double na = 0.0, ni = 0.0;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) {
      na += a[c][r] * a[c][r];
      ni += inv[c][r] * inv[c][r];
    }
  return std::sqrt(na * ni);
}

// The documented agreement of a hit through an instance with the same
// triangle of a pre-transformed copy (docs/scenes-and-instances.md,
// "Precision"): the hit points agree across the surface within
// 64 cond(A) 2^-24 (|o - T| + t |d| + |T| + the instance's world extent).
double point_tolerance(const Transform& t, const Ray& r, double hit_t, double extent) {
  const glm::dvec3 o(r.ox, r.oy, r.oz), d(r.dx, r.dy, r.dz), tr = translation_part(t);
  const double reach = glm::length(o - tr) + (std::isfinite(hit_t) ? hit_t * glm::length(d) : 0.0);
  return 64.0 * condition(t) * kFloatUlp * (reach + glm::length(tr) + extent);
}

glm::dvec3 unit_normal(const Geometry& g, int prim) {
  const glm::uvec3 tri = g.triangles[static_cast<std::size_t>(prim)];
  const glm::dvec3 a(g.vertices[tri.x]), b(g.vertices[tri.y]), c(g.vertices[tri.z]);
  return glm::normalize(glm::cross(b - a, c - a));
}

Geometry soup_mesh() {
  Geometry g = random_soup(1500, 21, 0.08f);
  g.source = "soup";
  return g;
}

// Rotations, mirroring and non-uniform scale, each placed apart.
std::vector<Transform> varied_transforms() {
  return {
      Transform::rotate(37, 1, 2, 3),
      Transform::translate(3, 0, 0) * Transform::scale(2, 0.5f, 1),
      Transform::translate(0, 3, 0) * Transform::scale(-1, 1, 1),
      Transform::translate(3, 3, 0) * Transform::rotate(-70, 0, 1, 1) * Transform::scale(0.25f, 1.5f, -1),
      Transform::translate(0, 0, 3) * Transform::rotate(120, 1, 1, 1) * Transform::scale(1, 1, 3),
      Transform::translate(1e4f, -2e4f, 3e4f) * Transform::rotate(20, 1, 0, 0) * Transform::scale(-1000, 1000, 1000),
      Transform::translate(-3, 0.5f, 0),
  };
}

// Each instance's hits match the same triangle of the pre-transformed copy
// traced by the flat BVH: the same primitive unless both answers are
// within the judge's ambiguity, hit points within point_tolerance across
// the surface, and the copy's double-precision judge passes.
TEST(TwoLevel, TransformedInstancesMatchAPreTransformedFlatCopy) {
  const Geometry mesh = soup_mesh();
  const std::vector<Transform> transforms = varied_transforms();
  const FlatInstances flat = flatten_instances(mesh, transforms);
  std::vector<Ray> rays;
  std::vector<std::uint32_t> aimed;  // the instance each ray aims at
  for (std::uint32_t k = 0; k < transforms.size(); ++k) {
    const FlatInstances one = flatten_instances(mesh, {transforms[k]});
    for (const Ray& r : random_rays(one.geometry, 1500, 100 + k)) {
      rays.push_back(r);
      aimed.push_back(k);
    }
  }
  const std::vector<Hit> references = reference_closest_all(flat.geometry, rays);
  for (Precision level : test_precisions()) {
    AccelConfig config;
    config.precision = level;
    auto copy = make_accel(test_device(), "bvh", flat.geometry, config);
    const std::vector<Hit> expected = copy->intersect(rays);
    Scene scene(test_device(), {level});
    MeshId id = scene.add_mesh(mesh);
    for (const Transform& t : transforms) scene.add_instance(id, t);
    scene.commit();
    std::vector<std::uint32_t> ids(rays.size());
    const std::vector<Hit> hits = scene.intersect(rays, ids);
    std::vector<Hit> mapped(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i)
      mapped[i] = hits[i].prim >= 0 ? flat_hit(flat, ids[i], hits[i]) : hits[i];
    expect_at_level(level, false, std::string("instances vs flat copy at ") + std::string(precision_name(level)), [&] {
      std::size_t failures = 0, differing = 0, far = 0, compared = 0;
      std::string first;
      std::vector<std::string> judged =
          judge_all(flat.geometry, rays, mapped, Query::closest, references, &failures, 3);
      for (std::size_t i = 0; i < rays.size(); ++i) {
        const Hit& h = mapped[i];
        const Hit& e = expected[i];
        if (h.prim != e.prim) {
          // Both must be acceptable answers (an edge, a grazing hit).
          if (!judge(flat.geometry, rays[i], e, Query::closest).empty() ||
              !judge(flat.geometry, rays[i], h, Query::closest).empty()) {
            if (differing++ == 0) first = "ray " + describe(rays[i]) + ": " + describe(h) + " vs copy " + describe(e);
          }
          continue;
        }
        if (h.prim < 0) continue;
        ++compared;
        const Transform& t = transforms[ids[i]];
        const double extent = glm::length(glm::dvec3(flat.boxes[ids[i]].extent()));
        const double across = std::abs(double{h.t} - double{e.t}) *
                              std::abs(glm::dot(glm::dvec3(rays[i].dx, rays[i].dy, rays[i].dz),
                                                unit_normal(flat.geometry, h.prim)));
        if (across > point_tolerance(t, rays[i], e.t, extent) && far++ == 0)
          first = "ray " + describe(rays[i]) + ": t " + std::to_string(h.t) + " vs copy " + std::to_string(e.t);
      }
      EXPECT_EQ(failures, 0u) << (judged.empty() ? "" : judged.front());
      EXPECT_EQ(differing, 0u) << first;
      EXPECT_EQ(far, 0u) << first;
      EXPECT_GT(compared, rays.size() / 5);
    });
  }
}

// ---------------------------------------------------------------------------
// Closed meshes through instances: rays from inside towards every vertex
// and edge midpoint of the placed mesh, and from outside through every
// vertex, must hit it (robust and exact; reported at fast).

struct ClosedMesh {
  Geometry mesh;
  glm::dvec3 inside;  // a point inside
  bool star;          // every ray from `inside` crosses the surface once
};

std::vector<ClosedMesh> closed_meshes() {
  return {{icosphere(3), glm::dvec3(0.0), true},
          {uv_sphere(24, 48), glm::dvec3(0.0), true},
          {cube_grid(8), glm::dvec3(0.0), true},
          {bumpy_sphere(3, 1.0f, 0.25f, 7), glm::dvec3(0.0), true},
          {staircase(4, 3), glm::dvec3(0.5), false}};
}

// Rotations, mirroring, non-uniform scale and large translations, placed
// far apart (each mesh is within radius 4 of its origin).
std::vector<Transform> leak_transforms() {
  return {
      Transform::rotate(33, 1, -2, 0.5f),
      Transform::translate(40, 0, 0) * Transform::scale(-1, 1, 1),
      Transform::translate(0, 40, 0) * Transform::scale(-1, 1, 1) * Transform::rotate(15, 0, 0, 1),
      Transform::translate(1e4f, -2e4f, 3e4f) * Transform::rotate(71, 0.3f, 1, -0.2f) * Transform::scale(1000),
      Transform::translate(-3e3f, 5e2f, 7e3f) * Transform::scale(3, 0.5f, 1.7f) * Transform::rotate(-40, 1, 1, 1),
      Transform::translate(2.5e5f, 1.25e5f, 0) * Transform::rotate(-17, 0, 1, 0),
      Transform::translate(-7e4f, 3e4f, 1e5f),  // a translation alone: the origin moves, the direction's setup stays
  };
}

// Instances of the closed mesh placed by `open` (moving to `close` when
// given; the rays are then traced at `time`): rays from the placed inside
// point to every target (vertices and edge midpoints), t = 1 at the
// target, ending at 1.5; for a mesh star-shaped from it, from outside
// through every vertex (4v - 3c towards c), t = 3 at the vertex, ending at
// 3.5. In object space every ray crosses the surface before its tmax: each
// must hit its own instance, at every level but fast (reported there).
void expect_no_leaks(const ClosedMesh& c, const std::vector<Transform>& open, const std::vector<Transform>& close,
                     float time) {
  ASSERT_EQ(open_edges(c.mesh), 0u) << c.mesh.source;
  const glm::dvec3 centre = c.inside;
  std::vector<glm::dvec3> targets;
  for (const glm::vec3& v : c.mesh.vertices) targets.emplace_back(v);
  for (auto [a, b] : unique_edges(c.mesh))
    targets.push_back(0.5 * (glm::dvec3(c.mesh.vertices[a]) + glm::dvec3(c.mesh.vertices[b])));
  std::vector<Ray> rays;
  std::vector<std::uint32_t> owner;
  for (std::uint32_t k = 0; k < open.size(); ++k) {
    const Transform placed = close.empty() ? open[k] : blend(open[k], close[k], time);
    const glm::vec3 o(apply(placed, centre));
    for (const glm::dvec3& target : targets) {
      const glm::vec3 p(apply(placed, target));
      rays.push_back(make_ray(o, p - o, 0.0f, 1.5f));
      owner.push_back(k);
    }
    for (const glm::vec3& v : c.mesh.vertices) {
      if (!c.star) break;
      const glm::dvec3 outside = 4.0 * glm::dvec3(v) - 3.0 * centre;
      const glm::dvec3 from = apply(placed, outside), to = apply(placed, centre);
      rays.push_back(make_ray(glm::vec3(from), glm::vec3((to - from) / 4.0), 0.0f, 3.5f));
      owner.push_back(k);
    }
  }
  const std::vector<float> times(close.empty() ? 0 : rays.size(), time);
  for (Precision level : test_precisions()) {
    for (const char* structure : {"bvh", "bvh-ploc"}) {
      Scene scene(test_device(), {level});
      MeshId id = scene.add_mesh(c.mesh, {structure, {}});
      for (std::size_t k = 0; k < open.size(); ++k)
        scene.add_instance({id, open[k], close.empty() ? std::nullopt : std::optional(close[k]), std::nullopt});
      scene.commit();
      for (Query query : {Query::closest, Query::any}) {
        std::vector<Hit> hits(rays.size());
        std::vector<std::uint32_t> ids(rays.size());
        scene.trace(query, rays, hits, ids, times);
        const std::string what = c.mesh.source + (close.empty() ? "" : " moving") + " " + structure + " " +
                                 std::string(precision_name(level)) + (query == Query::closest ? " closest" : " any");
        expect_at_level(level, false, what, [&] {
          std::size_t leaks = 0, wrong = 0;
          std::string first;
          for (std::size_t i = 0; i < rays.size(); ++i) {
            if (hits[i].prim < 0) {
              if (leaks++ == 0) first = "leak: instance " + std::to_string(owner[i]) + ", ray " + describe(rays[i]);
            } else if (ids[i] != owner[i] && wrong++ == 0) {
              first = "ray " + describe(rays[i]) + " of instance " + std::to_string(owner[i]) + " hit instance " +
                      std::to_string(ids[i]);
            }
          }
          EXPECT_EQ(leaks, 0u) << what << ", " << rays.size() << " rays; " << first;
          EXPECT_EQ(wrong, 0u) << what << "; " << first;
        });
      }
    }
  }
}

TEST(TwoLevel, ClosedInstancedMeshesDoNotLeak) {
  for (const ClosedMesh& c : closed_meshes()) expect_no_leaks(c, leak_transforms(), {}, 0.0f);
}

// The same through moving instances at a time inside the shutter: each
// transform of leak_transforms() moving to a turned, shifted and stretched
// one.
TEST(TwoLevel, ClosedMovingInstancesDoNotLeak) {
  const std::vector<Transform> open = leak_transforms();
  std::vector<Transform> close;
  for (const Transform& t : open)
    close.push_back(Transform::translate(2, -1, 0.5f) * t * Transform::rotate(25, 1, 0.5f, 0) *
                    Transform::scale(1.1f, 0.9f, 1));
  for (const ClosedMesh& c : closed_meshes())
    for (float time : {0.37f, 1.0f}) expect_no_leaks(c, open, close, time);
}

// Moving instances at fixed times: every answer judged against the
// double-precision reference of the instances' blended transforms at that
// time (times outside [0, 1] and NaN are clamped).
TEST(TwoLevel, MovingInstancesMatchTheReferenceAtFixedTimes) {
  const Geometry mesh = icosphere(2, 0.5f);
  struct Motion {
    Transform open, close;
  };
  const std::vector<Motion> motions = {
      {Transform::identity(), Transform::translate(1.0f, 0.5f, 0)},
      {Transform::translate(3, 0, 0), Transform::translate(3, 0, 0) * Transform::rotate(60, 0, 0, 1)},
      {Transform::translate(0, 3, 0), Transform::translate(0, 3, 0) * Transform::scale(1.5f, 1, 0.5f)},
      {Transform::translate(3, 3, 0) * Transform::scale(-1, 1, 1),
       Transform::translate(3.5f, 3, 1) * Transform::scale(-1, 2, 1) * Transform::rotate(30, 1, 0, 0)},
  };
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (Precision level : test_precisions()) {
    Scene scene(test_device(), {level});
    MeshId id = scene.add_mesh(mesh);
    for (const Motion& m : motions) scene.add_instance({id, m.open, m.close, std::nullopt});
    scene.add_instance(id, Transform::translate(1.5f, 1.5f, -2));  // a static one beside them
    scene.commit();
    for (float time : {0.0f, 0.3f, 0.5f, 1.0f, -0.5f, 2.0f, nan}) {
      const double at = std::isnan(time) ? 0.0 : std::clamp(double{time}, 0.0, 1.0);
      std::vector<Transform> placed;
      for (const Motion& m : motions) placed.push_back(blend(m.open, m.close, at));
      placed.push_back(Transform::translate(1.5f, 1.5f, -2));
      const FlatInstances flat = flatten_instances(mesh, placed);
      const std::vector<Ray> rays = random_rays(flat.geometry, 3000, 7 + static_cast<std::uint32_t>(at * 10));
      const std::vector<float> times(rays.size(), time);
      for (Query query : {Query::closest, Query::any}) {
        std::vector<Hit> hits(rays.size());
        std::vector<std::uint32_t> ids(rays.size());
        scene.trace(query, rays, hits, ids, times);
        std::vector<Hit> mapped(rays.size());
        std::size_t hit_count = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
          mapped[i] = hits[i].prim >= 0 ? flat_hit(flat, ids[i], hits[i]) : hits[i];
          hit_count += hits[i].prim >= 0;
        }
        const std::string what = "time " + std::to_string(time) + " " + std::string(precision_name(level)) +
                                 (query == Query::closest ? " closest" : " any");
        expect_at_level(level, false, what, [&] {
          std::size_t failures = 0;
          std::vector<std::string> judged = judge_all(flat.geometry, rays, mapped, query, &failures, 3);
          EXPECT_EQ(failures, 0u) << what << ": " << (judged.empty() ? "" : judged.front());
        });
        EXPECT_GT(hit_count, rays.size() / 10) << what;
      }
    }
  }
}

// Spheres of a mesh go through instances too: under a similarity they are
// spheres, checked against the reference of the moved spheres.
TEST(TwoLevel, SpheresThroughSimilarityTransforms) {
  Geometry mesh;
  mesh.source = "spheres";
  mesh.spheres = {{{0, 0, 0}, 0.5f}, {{1, 0, 0}, 0.25f}, {{0, 1, 0.5f}, 0.3f}};
  const std::vector<Transform> transforms = {Transform::translate(0, 0, 0) * Transform::rotate(45, 0, 0, 1),
                                             Transform::translate(5, 0, 0) * Transform::scale(2)};
  Geometry world;
  world.source = "spheres (placed)";
  for (const Transform& t : transforms) {
    const double s = std::cbrt(std::abs(glm::determinant(linear_part(t))));
    for (const Sphere& sp : mesh.spheres)
      world.spheres.push_back({glm::vec3(apply(t, glm::dvec3(sp.center))), static_cast<float>(sp.radius * s)});
  }
  const std::vector<Ray> rays = random_rays(world, 3000, 3);
  Scene scene(test_device());
  MeshId id = scene.add_mesh(mesh);
  for (const Transform& t : transforms) scene.add_instance(id, t);
  scene.commit();
  std::vector<std::uint32_t> ids(rays.size());
  std::vector<Hit> hits = scene.intersect(rays, ids);
  std::size_t hit_count = 0;
  for (std::size_t i = 0; i < rays.size(); ++i)
    if (hits[i].prim >= 0) {
      hits[i].prim += static_cast<std::int32_t>(ids[i] * mesh.spheres.size());
      ++hit_count;
    }
  std::size_t failures = 0;
  std::vector<std::string> judged = judge_all(world, rays, hits, Query::closest, &failures, 3);
  EXPECT_EQ(failures, 0u) << (judged.empty() ? "" : judged.front());
  EXPECT_GT(hit_count, rays.size() / 10);
}

// A scene of one transformed instance (its rays go to the bottom level
// without the top level's box test): closest and any hit judged against the
// double-precision reference on its pre-transformed copy, at every level.
TEST(TwoLevel, OneTransformedInstanceAnswersAsItsCopy) {
  const Geometry mesh = soup_mesh();
  for (const Transform& t : {varied_transforms()[3], varied_transforms()[5]}) {
    const FlatInstances flat = flatten_instances(mesh, {t});
    const std::vector<Ray> rays = random_rays(flat.geometry, 2000, 7);
    const std::vector<Hit> references = reference_closest_all(flat.geometry, rays);
    for (Precision level : test_precisions()) {
      Scene scene(test_device(), {level});
      scene.add_instance(scene.add_mesh(mesh), t);
      scene.commit();
      ASSERT_FALSE(scene.stats().single_level);
      std::vector<std::uint32_t> ids(rays.size());
      const std::vector<Hit> hits = scene.intersect(rays, ids);
      std::vector<Hit> any(rays.size());
      scene.trace(Query::any, rays, any);
      std::size_t hit_count = 0;
      for (std::size_t i = 0; i < rays.size(); ++i) {
        EXPECT_EQ(ids[i], hits[i].prim >= 0 ? 0u : kNoInstance);
        hit_count += hits[i].prim >= 0;
      }
      expect_at_level(level, false, "one instance at " + std::string(precision_name(level)), [&] {
        std::size_t closest_failures = 0, any_failures = 0;
        std::vector<std::string> closest =
            judge_all(flat.geometry, rays, hits, Query::closest, references, &closest_failures, 3);
        std::vector<std::string> blocked = judge_all(flat.geometry, rays, any, Query::any, &any_failures, 3);
        EXPECT_EQ(closest_failures, 0u) << (closest.empty() ? "" : closest.front());
        EXPECT_EQ(any_failures, 0u) << (blocked.empty() ? "" : blocked.front());
      });
      EXPECT_GT(hit_count, rays.size() / 5);
    }
  }
}

// An identity instance (its bottom level walked with the world ray), ones
// that only translate (the world ray's origin minus the translation, the
// direction's setup kept) and mirrored ones with the same kind of
// translations (their linear part is not the identity: the whole object
// ray): a cube with dyadic vertices at dyadic translations, axis-parallel
// rays through its vertices, edges and face planes with both signs of each
// zero component. Every map is exact, so at robust and exact each closest
// t equals brute force's on the pre-transformed copy bit for bit, and
// each query hits only where brute force does; every answer passes the
// double-precision judge.
TEST(TwoLevel, IdentityTranslatedAndMirroredInstancesAnswerAxisRaysExactly) {
  const Geometry cube = cube_grid(4);
  const std::vector<Transform> transforms = {
      Transform::identity(),
      Transform::translate(8, 0, 0),
      Transform::translate(0, -8, 0.5f),
      Transform::translate(0, 8, 0) * Transform::scale(-1, 1, 1),
      Transform::translate(-8, 0, 0) * Transform::scale(1, -1, 1),
      Transform::translate(0, 0, 8) * Transform::scale(-1, -1, -1),
  };
  std::vector<Ray> rays;
  for (const Transform& t : transforms)
    for (int axis = 0; axis < 3; ++axis)
      for (double sign : {1.0, -1.0})
        for (int j = 0; j <= 8; ++j)
          for (int k = 0; k <= 8; ++k)
            for (int zeros = 0; zeros < 4; ++zeros) {
              glm::dvec3 o(0.0), d(0.0);
              o[axis] = -3.0 * sign;
              o[(axis + 1) % 3] = -1.0 + 0.25 * j;
              o[(axis + 2) % 3] = -1.0 + 0.25 * k;
              d[axis] = sign;
              glm::vec3 world_d(linear_part(t) * d);
              world_d[(axis + 1) % 3] = (zeros & 1) ? -0.0f : 0.0f;
              world_d[(axis + 2) % 3] = (zeros & 2) ? -0.0f : 0.0f;
              rays.push_back(make_ray(glm::vec3(apply(t, o)), world_d, 0.0f, 5.0f));
            }
  const FlatInstances flat = flatten_instances(cube, transforms);
  for (Precision level : test_precisions()) {
    AccelConfig config;
    config.precision = level;
    auto brute = make_accel(test_device(), "brute", flat.geometry, config);
    Scene scene(test_device(), {level});
    const MeshId id = scene.add_mesh(cube);
    for (const Transform& t : transforms) scene.add_instance(id, t);
    scene.commit();
    for (Query query : {Query::closest, Query::any}) {
      std::vector<Hit> hits(rays.size());
      std::vector<std::uint32_t> ids(rays.size());
      scene.trace(query, rays, hits, ids);
      const std::vector<Hit> expected = run_query(*brute, rays, query);
      std::vector<Hit> mapped(rays.size());
      std::size_t hit_count = 0;
      for (std::size_t i = 0; i < rays.size(); ++i) {
        mapped[i] = hits[i].prim >= 0 ? flat_hit(flat, ids[i], hits[i]) : hits[i];
        hit_count += hits[i].prim >= 0;
      }
      const std::string what = std::string(precision_name(level)) + (query == Query::closest ? " closest" : " any");
      expect_at_level(level, false, what, [&] {
        std::size_t failures = 0;
        std::string first;
        const std::size_t differing = disagreements_with_brute(rays, mapped, expected, query, &first);
        std::vector<std::string> judged = judge_all(flat.geometry, rays, mapped, query, &failures, 3);
        EXPECT_EQ(differing, 0u) << what << ", " << rays.size() << " rays; first: " << first;
        EXPECT_EQ(failures, 0u) << what << ": " << (judged.empty() ? "" : judged.front());
      });
      EXPECT_GT(hit_count, rays.size() / 2) << what;
    }
  }
}

// The top level over instance boxes: every instance in exactly one leaf
// slot, every slot's box containing the boxes below it.
TEST(TwoLevel, TopLevelHoldsEveryInstanceOnce) {
  for (std::size_t count : {std::size_t{0}, std::size_t{1}, std::size_t{7}, std::size_t{9}, std::size_t{5000}}) {
    std::vector<Aabb> boxes;
    std::mt19937 rng(static_cast<std::uint32_t>(count));
    std::uniform_real_distribution<float> u(-100.0f, 100.0f);
    for (std::size_t i = 0; i < count; ++i) {
      glm::vec3 p(u(rng), u(rng), u(rng));
      boxes.push_back({p, p + glm::vec3(1.0f)});
    }
    TopLevel top = build_top_level(boxes);
    ASSERT_FALSE(top.nodes.empty());
    std::vector<int> seen(count, 0);
    std::vector<std::pair<std::int32_t, Aabb>> todo = {{0, Aabb{glm::vec3(-INFINITY), glm::vec3(INFINITY)}}};
    std::size_t visited = 0;
    while (!todo.empty()) {
      auto [node, parent] = todo.back();
      todo.pop_back();
      ++visited;
      for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
        const std::int32_t child = top.nodes[static_cast<std::size_t>(node)].child[lane];
        if (child == RTCL_CHILD_EMPTY) continue;
        const Aabb box = bvh8_lane_box(top.nodes[static_cast<std::size_t>(node)], lane);
        EXPECT_TRUE(parent.contains(box));
        if (child >= 0) {
          todo.push_back({child, box});
        } else {
          const auto k = static_cast<std::size_t>(~child);
          ASSERT_LT(k, count);
          ++seen[k];
          EXPECT_TRUE(box.contains(boxes[k]));
        }
      }
    }
    EXPECT_EQ(visited, top.nodes.size()) << count;
    for (std::size_t k = 0; k < count; ++k) ASSERT_EQ(seen[k], 1) << "instance " << k << " of " << count;
    EXPECT_GE(top.stack_size, 1u);
  }
}

}  // namespace
}  // namespace rtcl::test
