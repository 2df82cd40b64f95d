// One structure queried from 4 host threads at once (docs/api.md,
// "Threads"): 200 mixed calls each (closest, any, count, closest point, on
// host arrays and on OpenCL buffers), on a device opened for this test so
// that the first calls race to build the kernels. Every answer is checked
// against the same calls made from one thread on a structure of its own,
// whose closest hits are judged against the double-precision reference.
#include <gtest/gtest.h>

#include <cstring>
#include <thread>
#include <vector>

#include "rtcl/accel.hpp"
#include "support/closed_meshes.hpp"
#include "support/fixtures.hpp"
#include "support/reference.hpp"

namespace rtcl::test {
namespace {

template <class T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

struct Answers {
  std::vector<Hit> closest, any, closest_via_buffers;
  std::vector<std::uint32_t> counts;
  std::vector<PointHit> nearest;
};

Answers ask(const Accel& accel, const std::vector<Ray>& rays, const std::vector<glm::vec3>& points, int which) {
  Answers a;
  switch (which % 5) {
    case 0: a.closest = accel.intersect(rays); break;
    case 1:
      a.any.resize(rays.size());
      accel.trace(Query::any, rays, a.any);
      break;
    case 2: a.counts = accel.count(rays); break;
    case 3: a.nearest = accel.closest_points(points); break;
    case 4: a.closest_via_buffers = run_query(accel, rays, Query::closest); break;
  }
  return a;
}

TEST(AccelThreads, FourThreadsMixedCalls) {
  // A closed sphere with a soup of small triangles around it.
  Geometry mesh = icosphere(3);
  const Geometry soup = random_soup(500, 5, 0.2f);
  const glm::uvec3 offset(static_cast<std::uint32_t>(mesh.vertices.size()));
  mesh.vertices.insert(mesh.vertices.end(), soup.vertices.begin(), soup.vertices.end());
  for (const glm::uvec3& t : soup.triangles) mesh.triangles.push_back(t + offset);
  std::vector<Ray> rays = random_rays(mesh, 500, 9);
  std::vector<glm::vec3> points;
  for (const Ray& r : rays) points.emplace_back(r.ox * 0.5f, r.oy * 0.5f, r.oz * 0.5f);

  // The answers of one thread, on a structure of its own.
  auto serial = make_accel(test_device(), "bvh", mesh);
  std::vector<Answers> expected;
  for (int which = 0; which < 5; ++which) expected.push_back(ask(*serial, rays, points, which));
  std::size_t failures = 0;
  judge_all(mesh, rays, expected[0].closest, Query::closest, &failures);
  ASSERT_EQ(failures, 0u);
  ASSERT_TRUE(same_bytes(expected[0].closest, expected[4].closest_via_buffers));

  Device fresh = Device::open();  // its own program cache: the first calls below race to build
  auto shared = make_accel(fresh, "bvh", mesh);
  constexpr int kThreads = 4, kCalls = 200;
  std::vector<int> wrong(kThreads, 0);
  std::vector<std::string> errors(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      try {
        for (int call = 0; call < kCalls; ++call) {
          const int which = (call + t * 3) % 5;  // threads start on different queries
          Answers got = ask(*shared, rays, points, which);
          const Answers& want = expected[which];
          const bool ok = same_bytes(got.closest, want.closest) && same_bytes(got.any, want.any) &&
                          same_bytes(got.counts, want.counts) && same_bytes(got.nearest, want.nearest) &&
                          same_bytes(got.closest_via_buffers, want.closest_via_buffers);
          wrong[t] += !ok;
        }
      } catch (const std::exception& e) {
        errors[t] = e.what();
      }
    });
  for (std::thread& thread : threads) thread.join();
  for (int t = 0; t < kThreads; ++t) {
    EXPECT_EQ(errors[t], "") << "thread " << t;
    EXPECT_EQ(wrong[t], 0) << "thread " << t << ": calls with a wrong answer";
  }
}

}  // namespace
}  // namespace rtcl::test
