// Queries on host arrays (Accel::trace / intersect / occluded with Rays):
// the same answers as the cl::Buffer path and the double-precision
// reference, from Ray records and from separate arrays, in batches across
// the device's buffer limit on both of HostBatches' ways, and bad input
// refused before any output is written.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>
#include <vector>

#include "rtcl/accel.hpp"
#include "support/error_of.hpp"
#include "support/everywhere.hpp"
#include "support/fixtures.hpp"
#include "support/reference.hpp"
#include "support/scoped_env.hpp"

namespace rtcl::test {
namespace {

using everywhere::query_name;

// Origins, directions, tmin and tmax of the rays as separate arrays.
struct SoaRays {
  std::vector<float> origins, directions, tmin, tmax;
  explicit SoaRays(const std::vector<Ray>& rays) {
    for (const Ray& r : rays) {
      origins.insert(origins.end(), {r.ox, r.oy, r.oz});
      directions.insert(directions.end(), {r.dx, r.dy, r.dz});
      tmin.push_back(r.tmin);
      tmax.push_back(r.tmax);
    }
  }
};

// Rays at the tiny quad [-1, 1]^2 x {0}, with invalid ones mixed in.
std::vector<Ray> quad_rays(std::size_t count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> xy(-1.5f, 1.5f);
  std::vector<Ray> rays(count);
  for (std::size_t i = 0; i < count; ++i) {
    rays[i] = make_ray({xy(rng), xy(rng), 1.0f}, {0.01f * xy(rng), 0.01f * xy(rng), -1.0f});
    if (i % 97 == 5) rays[i].dx = kNaN;
    if (i % 101 == 7) rays[i].dx = rays[i].dy = rays[i].dz = 0.0f;
    if (i % 103 == 9) rays[i].tmax = 0.5f;  // ends above the quad
  }
  return rays;
}

Geometry quad() {
  const float xyz[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  const std::uint32_t indices[] = {0, 1, 2, 0, 2, 3};
  return Geometry::from_arrays(xyz, 4, indices, 2, "quad");
}

TEST(HostArrays, SameAsBufferPathAndReference) {
  Geometry soup = random_soup(3000, 11);
  std::vector<Ray> rays = random_rays(soup, 4000, 12);
  for (const std::string& name : {"bvh", "grid", "kdtree"}) {
    auto accel = make_accel(test_device(), name, soup);
    for (Query query : {Query::closest, Query::any}) {
      std::vector<Hit> via_buffers = run_query(*accel, rays, query);
      std::vector<Hit> hits(rays.size());
      accel->trace(query, rays, hits);
      SoaRays soa(rays);
      std::vector<Hit> soa_hits(rays.size());
      accel->trace(query, Rays(soa.origins, soa.directions, soa.tmin, soa.tmax), soa_hits);
      std::size_t differ = 0;
      for (std::size_t i = 0; i < rays.size(); ++i)
        differ += !same_bits(hits[i], via_buffers[i]) || !same_bits(soa_hits[i], via_buffers[i]);
      EXPECT_EQ(differ, 0u) << name << " " << query_name(query);
      std::size_t failures = 0;
      std::vector<std::string> report = judge_all(soup, rays, hits, query, &failures);
      EXPECT_EQ(failures, 0u) << name << " " << query_name(query) << ": " << (report.empty() ? "" : report[0]);
    }
    std::vector<std::uint8_t> blocked = accel->occluded(rays);
    std::vector<Hit> closest = accel->intersect(rays);
    for (std::size_t i = 0; i < rays.size(); ++i)
      ASSERT_EQ(blocked[i] != 0, closest[i].prim >= 0) << name << " ray " << i;
  }
}

TEST(HostArrays, DefaultIntervalIsZeroToInfinity) {
  auto accel = make_accel(test_device(), "bvh", quad());
  const float origins[] = {0.25f, 0.5f, 1.0f, 0.25f, 0.5f, -1.0f};
  const float directions[] = {0, 0, -1, 0, 0, -1};
  std::vector<Hit> hits = accel->intersect(Rays(origins, directions));
  EXPECT_EQ(hits[0].t, 1.0f);
  EXPECT_EQ(hits[0].prim, 1);
  EXPECT_EQ(hits[1].prim, -1);  // the quad lies behind its origin (t = -1 < tmin = 0)
}

// Many rays through a device whose largest buffer holds 128 rays: every
// batch's answers are those of one launch on the unrestricted device, on
// both ways of HostBatches (the caller's memory, and copies through two
// slots of device buffers).
TEST(HostArrays, BatchesAcrossTheBufferLimit) {
  Geometry mesh = quad();
  std::vector<Ray> rays = quad_rays(10007, 3);
  auto full = make_accel(test_device(), "bvh", mesh);
  std::vector<Hit> one_launch = run_query(*full, rays, Query::closest);
  std::vector<Hit> one_launch_any = run_query(*full, rays, Query::any);
  std::size_t hit_count = 0;
  for (const Hit& h : one_launch) hit_count += h.prim >= 0;
  ASSERT_GT(hit_count, rays.size() / 3);

  for (const char* mode : {"shared", "copy"}) {
    ScopedEnv alloc("RTCL_MAX_ALLOC_BYTES", "4096");
    ScopedEnv host_arrays("RTCL_HOST_ARRAYS", mode);
    Device small = Device::open();
    ASSERT_EQ(small.info().max_alloc_bytes, 4096u);
    auto accel = make_accel(small, "bvh", mesh);
    std::vector<Hit> hits = accel->intersect(rays);
    SoaRays soa(rays);
    std::vector<Hit> any(rays.size());
    accel->trace(Query::any, Rays(soa.origins, soa.directions, soa.tmin, soa.tmax), any);
    std::size_t differ = 0, differ_any = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      differ += !same_bits(hits[i], one_launch[i]);
      differ_any += !same_bits(any[i], one_launch_any[i]);
    }
    EXPECT_EQ(differ, 0u) << mode;
    EXPECT_EQ(differ_any, 0u) << mode;
    for (std::size_t i = 0; i < rays.size(); ++i)
      if (std::isnan(rays[i].dx) || (rays[i].dx == 0 && rays[i].dy == 0 && rays[i].dz == 0))
        ASSERT_EQ(hits[i].prim, -1) << mode << ": invalid ray " << i << " is a miss";
  }
}

TEST(HostArrays, BadInputIsRefusedBeforeAnyOutput) {
  auto accel = make_accel(test_device(), "bvh", quad());
  std::vector<Ray> rays = quad_rays(8, 1);
  const Hit untouched{-7.0f, -7.0f, -7.0f, -7};
  std::vector<Hit> hits(7, untouched);
  std::string e = error_of([&] { accel->trace(Query::closest, rays, hits); });
  EXPECT_NE(e.find("intersect: hits holds 7 records for 8 rays"), std::string::npos) << e;
  for (const Hit& h : hits) ASSERT_TRUE(same_bits(h, untouched));

  std::vector<float> xyz(9, 0.0f), short_dirs(6, 1.0f), two(2, 0.0f);
  e = error_of([&] { Rays bad(std::span<const float>(xyz.data(), 8), xyz); });
  EXPECT_NE(e.find("rays: origins holds 8 floats, not 3 per ray"), std::string::npos) << e;
  e = error_of([&] { Rays bad(xyz, short_dirs); });
  EXPECT_NE(e.find("rays: directions holds 6 floats, origins 9"), std::string::npos) << e;
  e = error_of([&] { Rays bad(xyz, xyz, two); });
  EXPECT_NE(e.find("rays: tmin holds 2 values for 3 rays"), std::string::npos) << e;
  e = error_of([&] { Rays bad(xyz, xyz, {}, two); });
  EXPECT_NE(e.find("rays: tmax holds 2 values for 3 rays"), std::string::npos) << e;
  e = error_of([&] { Rays bad(std::span<const float>(static_cast<const float*>(nullptr), 9), xyz); });
  EXPECT_NE(e.find("rays: null origins or directions"), std::string::npos) << e;
  e = error_of([&] { Points bad(std::span<const float>(xyz.data(), 4)); });
  EXPECT_NE(e.find("points: holds 4 floats, not 3 per point"), std::string::npos) << e;

  // No rays: nothing to do, nothing written.
  EXPECT_TRUE(accel->intersect(std::vector<Ray>{}).empty());
}

}  // namespace
}  // namespace rtcl::test
