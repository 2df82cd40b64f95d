// SortChoice (rtcl/accel/sort_choice.hpp) against its contract, and an
// Accel's scattered calls under each ScatteredSort: which calls sort, and
// that every call, sorted or not, gives brute force's closest hits.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/accel/sort_choice.hpp"
#include "support/fixtures.hpp"

namespace rtcl {
namespace {

using test::random_rays;
using test::random_soup;
using test::run_query;
using test::test_device;

TEST(SortChoice, MeasuredTriesBothWaysThenTakesTheFasterAndExploresTheOther) {
  static_assert(SortChoice::kFirstMeasurements == 2);
  SortChoice choice;
  EXPECT_FALSE(choice.settled());
  EXPECT_TRUE(choice.next()) << "sorted until two sorted calls are measured";
  choice.record(true, 3.0);
  EXPECT_TRUE(choice.next());
  choice.record(true, 1.0);  // kept: the mean, 2.0
  EXPECT_DOUBLE_EQ(choice.ms_per_ray(true), 2.0);
  EXPECT_FALSE(choice.next()) << "then unsorted until two unsorted ones are";
  choice.record(false, 1.0);
  EXPECT_FALSE(choice.settled());
  EXPECT_FALSE(choice.next());
  choice.record(false, 1.0);
  EXPECT_TRUE(choice.settled());
  int sorted = 0;
  for (int i = 0; i < 4 * SortChoice::kExplorePeriod; ++i) sorted += choice.next();
  EXPECT_EQ(sorted, 4) << "the slower way once every kExplorePeriod choices";
  choice.record(true, 0.2);  // kept: (2.0 + 0.2) / 2 = 1.1, still slower
  EXPECT_DOUBLE_EQ(choice.ms_per_ray(true), 1.1);
  EXPECT_FALSE(choice.next());
  choice.record(true, 0.5);  // kept: 0.8
  EXPECT_TRUE(choice.next());
  choice.record(false, 0.8);  // kept: 0.9
  EXPECT_TRUE(choice.next());
  choice.record(false, 0.7);  // kept: 0.8, a tie: sorted
  EXPECT_TRUE(choice.next());
}

TEST(SortChoice, IgnoresTimesThatAreNotPositive) {
  SortChoice choice;
  choice.record(true, 0.0);
  choice.record(true, -1.0);
  EXPECT_TRUE(choice.next()) << "nothing measured yet";
  EXPECT_DOUBLE_EQ(choice.ms_per_ray(true), 0.0);
}

TEST(SortChoice, AlwaysAndNeverIgnoreTheTimes) {
  SortChoice always(ScatteredSort::always), never(ScatteredSort::never);
  for (double ms : {1.0, 100.0}) {
    always.record(true, ms);
    always.record(false, 1.0 / ms);
    never.record(false, ms);
    never.record(true, 1.0 / ms);
    for (int i = 0; i < 2 * SortChoice::kExplorePeriod; ++i) {
      EXPECT_TRUE(always.next());
      EXPECT_FALSE(never.next());
      EXPECT_TRUE(always.settled());
    }
  }
}

TEST(ScatteredCalls, MeasuredSortsThenNotThenTakesTheFasterAndAnswersAlike) {
  Geometry g = random_soup(3000, 7);
  std::vector<Ray> rays = random_rays(g, 20'000, 11);
  const Device& device = test_device();
  std::vector<Hit> expected = run_query(*make_accel(device, "brute", g), rays, Query::closest);
  std::unique_ptr<Accel> accel = make_accel(device, "bvh", g);
  if (!accel->sorts(Coherence::scattered)) GTEST_SKIP() << "scattered calls sort on CPU devices only";
  EXPECT_FALSE(accel->sort_choice_settled(Query::closest));
  EXPECT_TRUE(make_accel(device, "bvh", g, {Precision::robust, {}, ScatteredSort::always})->sort_choice_settled(Query::closest));
  run_query(*accel, rays, Query::closest);  // the unsorted kernel's first launch
  for (int call = 0; call < 7; ++call) {
    SCOPED_TRACE("call " + std::to_string(call));
    std::vector<Hit> hits = run_query(*accel, rays, Query::closest, Coherence::scattered);
    // the sorted kernel's first launch is not measured (code generation,
    // first touch); the unsorted one launched before, incoherent
    if (call <= 2) EXPECT_TRUE(accel->last_call_sorted());
    if ((call == 3 || call == 4) && device.profiling()) EXPECT_FALSE(accel->last_call_sorted());
    if (call == 5 && device.profiling()) EXPECT_TRUE(accel->sort_choice_settled(Query::closest));
    std::size_t differing = 0;
    for (std::size_t i = 0; i < rays.size(); ++i)
      differing += (hits[i].prim < 0) != (expected[i].prim < 0) || (hits[i].prim >= 0 && hits[i].t != expected[i].t);
    EXPECT_EQ(differing, 0u);
  }
  run_query(*accel, rays, Query::closest);
  EXPECT_FALSE(accel->last_call_sorted()) << "an incoherent call never sorts";
}

TEST(ScatteredCalls, NeverSortsWithNever) {
  Geometry g = random_soup(500, 3);
  std::unique_ptr<Accel> accel = make_accel(test_device(), "bvh", g, {Precision::robust, {}, ScatteredSort::never});
  EXPECT_FALSE(accel->sorts(Coherence::scattered));
  std::vector<Ray> rays = random_rays(g, 1000, 5);
  for (int call = 0; call < 3; ++call) {
    run_query(*accel, rays, Query::any, Coherence::scattered);
    EXPECT_FALSE(accel->last_call_sorted());
  }
}

}  // namespace
}  // namespace rtcl
