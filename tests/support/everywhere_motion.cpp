// The motion pass of the registry-wide driver (everywhere.hpp,
// run_through_motion): the geometry as the mesh of moving instances of a
// two-level scene (rtcl/scene.hpp), traced with the suite's own rays.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "rtcl/scene.hpp"
#include "support/everywhere.hpp"
#include "support/fixtures.hpp"
#include "support/instances.hpp"
#include "support/reference.hpp"

namespace rtcl::test::everywhere {

namespace {

// The shutter times at which the motion's blend is exactly the identity
// (kIdentityTime) and the others the pass traces: with the motion's dyadic
// elements, the kernel's float blend open + t (close - open) is exact at
// each of them, so the reference's transform is the kernel's.
constexpr float kIdentityTime = 0.5f;
constexpr std::array<float, 4> kOtherTimes = {0.0f, 0.25f, 0.75f, 1.0f};

struct Motion {
  Transform open, close;
};

// open = I - S, close = I + S, translations -a and +a: at time 0.5 the
// element-wise blend is the identity, bit for bit. S turns, shears and
// scales (spectral norm below 1/2, so every blend is invertible and keeps
// its orientation); for a geometry with spheres it is a uniform scale
// (every blend a similarity, under which a sphere stays a sphere). a is
// a power of two near the geometry's extent.
Motion motion_for(const Geometry& geometry) {
  const glm::vec3 extent = geometry.bounds().extent();
  const float size = std::max({extent.x, extent.y, extent.z});
  const float unit = std::isfinite(size) && size > 0.0f ? std::exp2(std::floor(std::log2(size))) : 1.0f;
  std::array<std::array<float, 3>, 3> s = {{{0.25f, -0.125f, 0.0625f}, {0.125f, -0.125f, 0.0f}, {0.0f, 0.0625f, 0.125f}}};
  if (!geometry.spheres.empty()) s = {{{0.25f, 0.0f, 0.0f}, {0.0f, 0.25f, 0.0f}, {0.0f, 0.0f, 0.25f}}};
  const std::array<float, 3> a = {0.5f * unit, -0.25f * unit, 0.75f * unit};
  Motion m;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) {
      const float diagonal = row == col ? 1.0f : 0.0f;
      m.open.m[row][col] = diagonal - s[row][col];
      m.close.m[row][col] = diagonal + s[row][col];
    }
    m.open.m[row][3] = -a[row];
    m.close.m[row][3] = a[row];
  }
  return m;
}

// The transform's linear part A in double.
glm::dmat3 linear_part_of(const Transform& t) {
  glm::dmat3 a;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) a[col][row] = t.m[row][col];  // glm is column-major
  return a;
}

// The geometry placed by `t` (double, rounded to float once); spheres
// (under a similarity only) with their centres moved and radii scaled.
Geometry placed(const Geometry& geometry, const Transform& t) {
  Geometry out = geometry;
  for (glm::vec3& v : out.vertices) v = glm::vec3(apply(t, glm::dvec3(v)));
  const double scale = std::cbrt(std::abs(glm::determinant(linear_part_of(t))));
  for (Sphere& sphere : out.spheres) {
    sphere.center = glm::vec3(apply(t, glm::dvec3(sphere.center)));
    sphere.radius = static_cast<float>(sphere.radius * scale);
  }
  out.source = geometry.source + " (moved)";
  return out;
}

// The ray placed by `t`: o -> A o + T, d -> A d (double, rounded once);
// tmin and tmax stay, as t does under the map.
Ray placed(const Ray& r, const Transform& t) {
  const glm::dvec3 o = apply(t, glm::dvec3(r.ox, r.oy, r.oz));
  const glm::dvec3 d = linear_part_of(t) * glm::dvec3(r.dx, r.dy, r.dz);
  return make_ray(glm::vec3(o), glm::vec3(d), r.tmin, r.tmax);
}

}  // namespace

void run_through_motion(const Geometry& geometry, const std::vector<Ray>& rays, const Check& check,
                        const RunOptions& options) {
  const Motion motion = motion_for(geometry);
  // Ray i at kOtherTimes[i % 4], placed in the world of its time.
  std::vector<Ray> moved(rays.size());
  std::vector<float> other_times(rays.size());
  std::array<Transform, kOtherTimes.size()> at;
  for (std::size_t k = 0; k < kOtherTimes.size(); ++k) at[k] = blend(motion.open, motion.close, kOtherTimes[k]);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    other_times[i] = kOtherTimes[i % kOtherTimes.size()];
    moved[i] = placed(rays[i], at[i % kOtherTimes.size()]);
  }
  std::array<Geometry, kOtherTimes.size()> worlds;
  for (std::size_t k = 0; k < kOtherTimes.size(); ++k) worlds[k] = placed(geometry, at[k]);
  const std::vector<float> identity_times(rays.size(), kIdentityTime);
  for (Precision level : test_precisions()) {
    // Two coincident instances with the same motion: the rays go through
    // the top level (one instance would skip it) and meet both.
    Scene scene(test_device(), {level});
    const MeshId mesh = scene.add_mesh(geometry);
    for (int copy = 0; copy < 2; ++copy) scene.add_instance({mesh, motion.open, motion.close, std::nullopt});
    scene.commit();
    std::vector<Hit> references;
    if (level == Precision::fast && options.judge && options.fast_bound)
      references = reference_closest_all(geometry, rays);
    for (Query query : {Query::closest, Query::any}) {
      const std::string what = "moving instances " + std::string(precision_name(level)) + " " + query_name(query) +
                               " on " + geometry.source;
      SCOPED_TRACE(what);
      // At the identity time: the suite's rays and expectations unchanged.
      std::vector<Hit> hits(rays.size());
      scene.trace(query, rays, hits, {}, identity_times);
      expect_at_level(level, options.fast_must_pass, what + " at the identity time", [&] {
        if (options.judge) {
          std::size_t failures = 0;
          std::vector<std::string> report = judge_all(geometry, rays, hits, query, &failures);
          EXPECT_EQ(failures, 0u) << "answers the double-precision reference rejects; first: "
                                  << (report.empty() ? "" : report.front());
        }
        if (check) check("moving instances", query, hits);
      });
      if (!references.empty())
        expect_within_fast_bound(geometry, rays, hits, query, references, what + " at the identity time");
      // At the other times, each ray in the world of its own time: the
      // judge of that world, and no leak where every ray must hit.
      std::vector<Hit> moved_hits(rays.size());
      scene.trace(query, moved, moved_hits, {}, other_times);
      expect_at_level(level, options.fast_must_pass && !options.every_ray_hits, what + " at other times", [&] {
        std::size_t failures = 0, leaks = 0;
        std::string first_failure, first_leak;
        for (std::size_t k = 0; k < kOtherTimes.size(); ++k) {
          std::vector<Ray> group_rays;
          std::vector<Hit> group_hits;
          for (std::size_t i = k; i < rays.size(); i += kOtherTimes.size()) {
            group_rays.push_back(moved[i]);
            group_hits.push_back(moved_hits[i]);
            if (options.every_ray_hits && moved_hits[i].prim < 0 && leaks++ == 0)
              first_leak = "time " + std::to_string(kOtherTimes[k]) + ", ray " + describe(moved[i]) +
                           " (at the identity time " + describe(rays[i]) + ")";
          }
          if (!options.judge || !options.judge_moved) continue;
          std::size_t group_failures = 0;
          std::vector<std::string> report = judge_all(worlds[k], group_rays, group_hits, query, &group_failures, 1);
          if (group_failures > 0 && failures == 0)
            first_failure = "time " + std::to_string(kOtherTimes[k]) + ": " + report.front();
          failures += group_failures;
        }
        EXPECT_EQ(failures, 0u) << "answers the double-precision reference rejects; first: " << first_failure;
        EXPECT_EQ(leaks, 0u) << "rays that must hit missed; first: " << first_leak;
      });
    }
  }
}

}  // namespace rtcl::test::everywhere
