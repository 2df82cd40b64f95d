#include <gtest/gtest.h>

#include "rtcl/accel/brute.hpp"
#include "support/fixtures.hpp"
#include "support/reference.hpp"

namespace rtcl::test {
namespace {

TEST(Brute, RandomSoupMatchesReference) {
  Geometry g = random_soup(300, 1);
  auto rays = random_rays(g, 2000, 2);
  auto accel = make_brute(test_device(), g);
  for (Query q : {Query::closest, Query::any}) {
    auto hits = run_query(*accel, rays, q);
    std::size_t failures = 0;
    auto report = judge_all(g, rays, hits, q, &failures);
    EXPECT_EQ(failures, 0u) << (report.empty() ? "" : report[0]);
  }
}

}  // namespace
}  // namespace rtcl::test
