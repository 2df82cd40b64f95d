// RaySort (rtcl/accel/ray_sort.hpp) against its contract, checked with keys
// computed on the host from the definition in kernels/accel/ray_sort.cl: the
// order is a permutation, keys never decrease along it and equal keys keep
// their input order. Rays
// include NaN and infinite origins, origins outside the box and +-0
// direction components. Coherence::scattered calls of every structure are
// compared with brute force by run_everywhere (support/everywhere.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/accel/ray_sort.hpp"
#include "support/fixtures.hpp"

namespace rtcl {
namespace {

using test::random_soup;
using test::test_device;

// The key of kernels/accel/ray_sort.cl from its definition: each origin
// coordinate's cell on 2^bits cells over [lower, upper] (clamped; NaN ->
// 0), Morton-interleaved x highest, then the three direction sign bits.
std::uint32_t host_key(const Ray& r, const Aabb& box, int bits) {
  const int cells = 1 << bits;
  auto cell = [&](float o, float lo, float hi) {
    double scale = hi > lo ? cells / (static_cast<double>(hi) - lo) : 0.0;
    double f = (static_cast<double>(o) - lo) * scale;
    if (!(f > 0.0)) return 0;
    return static_cast<int>(std::min<double>(cells - 1, std::floor(f)));
  };
  int c[3] = {cell(r.ox, box.lower.x, box.upper.x), cell(r.oy, box.lower.y, box.upper.y),
              cell(r.oz, box.lower.z, box.upper.z)};
  std::uint32_t morton = 0;
  for (int b = bits - 1; b >= 0; --b)
    for (int a = 0; a < 3; ++a) morton = morton << 1 | ((c[a] >> b) & 1);
  return morton << 3 | std::uint32_t{std::signbit(r.dx)} << 2 | std::uint32_t{std::signbit(r.dy)} << 1 |
         std::uint32_t{std::signbit(r.dz)};
}

std::vector<Ray> awkward_rays(std::size_t n, const Aabb& box) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.25f, 1.25f), d(-1.0f, 1.0f);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  std::vector<Ray> rays(n);
  for (std::size_t i = 0; i < n; ++i) {
    glm::vec3 e = box.upper - box.lower;
    Ray& r = rays[i];
    r = {box.lower.x + u(rng) * e.x, box.lower.y + u(rng) * e.y, box.lower.z + u(rng) * e.z, d(rng), d(rng), d(rng),
         0.0f, inf};
    switch (i % 11) {
      case 0: r.ox = nan; break;
      case 1: r.oy = -inf; break;
      case 2: r.oz = inf; break;
      case 3: r.dx = -0.0f; r.dy = 0.0f; break;
      case 4: r.dz = -0.0f; break;
      case 5: r.ox = box.upper.x; r.oy = box.lower.y; break;  // on the box's faces
      default: break;
    }
    if (i % 97 == 0 && i > 0) rays[i] = rays[i - 1];  // equal keys in a row
  }
  return rays;
}

void expect_sorted(const std::vector<Ray>& rays, const Aabb& box, int bits) {
  const Device& device = test_device();
  RaySort sort(device, box, bits);
  cl::Buffer buffer = device.upload(rays.data(), rays.size() * sizeof(Ray), "rays");
  std::vector<cl::Event> passes = sort.enqueue(buffer, rays.size(), {});
  std::vector<std::uint32_t> order(rays.size());
  device.queue().enqueueReadBuffer(sort.order(), CL_TRUE, 0, order.size() * sizeof(std::uint32_t), order.data(),
                                   &passes);
  std::vector<bool> seen(rays.size(), false);
  std::size_t bad_key = 0, unstable = 0;
  for (std::size_t k = 0; k < rays.size(); ++k) {
    ASSERT_LT(order[k], rays.size()) << "order[" << k << "]";
    ASSERT_FALSE(seen[order[k]]) << "ray " << order[k] << " twice in the order";
    seen[order[k]] = true;
    if (k > 0) {
      std::uint32_t a = host_key(rays[order[k - 1]], box, bits), b = host_key(rays[order[k]], box, bits);
      bad_key += a > b;
      unstable += a == b && order[k - 1] > order[k];
    }
  }
  EXPECT_EQ(bad_key, 0u) << "places where the key decreases";
  EXPECT_EQ(unstable, 0u) << "equal keys out of input order";
}

TEST(RaySort, SortsByOriginCellAndOctantStably) {
  const Aabb box{{-1.0f, 2.0f, -3.0f}, {4.0f, 2.5f, 0.0f}};
  for (int bits : {0, 1, 3})
    for (std::size_t n : {std::size_t{1}, std::size_t{4095}, std::size_t{50'021}}) {
      SCOPED_TRACE("origin bits " + std::to_string(bits) + ", " + std::to_string(n) + " rays");
      expect_sorted(awkward_rays(n, box), box, bits);
    }
}

TEST(RaySort, FlatAndEmptyBoxesSortByOctant) {
  const Aabb flat{{0.0f, 0.0f, 1.0f}, {1.0f, 1.0f, 1.0f}};  // no extent in z
  expect_sorted(awkward_rays(9000, flat), flat, 3);
  expect_sorted(awkward_rays(9000, Aabb{}), Aabb{}, 3);
}

TEST(RaySort, RejectsOriginBitsOutOfRange) {
  EXPECT_THROW(RaySort(test_device(), Aabb{}, 5), Error);
  EXPECT_THROW(RaySort(test_device(), Aabb{}, -1), Error);
  RaySort sort(test_device(), Aabb{});
  cl::Buffer one = test_device().allocate(sizeof(Ray), "one ray");
  EXPECT_THROW(sort.enqueue(one, 0, {}), Error);
}

TEST(RaySort, ScatteredCallTimesTheSortAndTheTrace) {
  Geometry g = random_soup(2000, 1);
  std::unique_ptr<Accel> accel = make_accel(test_device(), "bvh", g, {Precision::robust, {}, ScatteredSort::always});
  if (!accel->sorts(Coherence::scattered)) GTEST_SKIP() << "scattered calls sort on CPU devices only";
  std::vector<Ray> rays = awkward_rays(20'000, g.bounds());
  const Device& device = test_device();
  cl::Buffer ray_buffer = device.upload(rays.data(), rays.size() * sizeof(Ray), "rays");
  cl::Buffer hit_buffer = device.allocate(rays.size() * sizeof(Hit), "hits");
  cl::Event done = accel->trace(Query::closest, ray_buffer, hit_buffer, rays.size(), {}, Coherence::scattered);
  done.wait();
  if (!device.profiling()) GTEST_SKIP() << "no profiling queue";
  cl_ulong first_start = accel->first_event().getProfilingInfo<CL_PROFILING_COMMAND_START>();
  cl_ulong trace_start = done.getProfilingInfo<CL_PROFILING_COMMAND_START>();
  EXPECT_LT(first_start, trace_start) << "the sort's first pass starts before the trace";
  EXPECT_DOUBLE_EQ(accel->last_call_ms(done),
                   static_cast<double>(done.getProfilingInfo<CL_PROFILING_COMMAND_END>() - first_start) * 1e-6);
  cl::Event plain = accel->trace(Query::closest, ray_buffer, hit_buffer, rays.size());
  plain.wait();
  EXPECT_EQ(accel->first_event().getProfilingInfo<CL_PROFILING_COMMAND_START>(),
            plain.getProfilingInfo<CL_PROFILING_COMMAND_START>());
}

}  // namespace
}  // namespace rtcl
