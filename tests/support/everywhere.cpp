#include "support/everywhere.hpp"

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <utility>

#include "support/fixtures.hpp"
#include "support/reference.hpp"

namespace rtcl::test::everywhere {

std::string describe(const Ray& r) {
  std::ostringstream s;
  s.precision(9);
  s << "o=(" << r.ox << "," << r.oy << "," << r.oz << ") d=(" << r.dx << "," << r.dy << "," << r.dz << ") t=["
    << r.tmin << "," << r.tmax << "]";
  return s.str();
}

std::string describe(const Hit& h) {
  std::ostringstream s;
  s.precision(9);
  s << "prim " << h.prim << " t=" << h.t;
  return s.str();
}

const char* query_name(Query q) { return q == Query::closest ? "closest" : "any"; }

std::size_t disagreements_with_brute(const std::vector<Ray>& rays, const std::vector<Hit>& hits,
                                     const std::vector<Hit>& brute, Query query, std::string* first) {
  std::size_t count = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const bool same = (hits[i].prim < 0) == (brute[i].prim < 0) &&
                      (query == Query::any || hits[i].prim < 0 || hits[i].t == brute[i].t);
    if (!same && count++ == 0)
      *first = "ray " + std::to_string(i) + " " + describe(rays[i]) + ": " + describe(hits[i]) + ", brute force " +
               describe(brute[i]);
  }
  return count;
}

void expect_at_level(Precision level, bool must_pass, const std::string& what, const std::function<void()>& evaluate) {
  if (level != Precision::fast || must_pass) return evaluate();
  testing::TestPartResultArray results;
  {
    testing::ScopedFakeTestPartResultReporter reporter(
        testing::ScopedFakeTestPartResultReporter::INTERCEPT_ONLY_CURRENT_THREAD, &results);
    evaluate();
  }
  if (results.size() > 0) {
    std::string first = results.GetTestPartResult(0).message();
    std::replace(first.begin(), first.end(), '\n', ' ');
    if (first.size() > 400) first = first.substr(0, 400) + "...";
    std::printf("[fast] %s: %d expectation(s) not met (allowed at the fast level); first: %s\n", what.c_str(),
                results.size(), first.c_str());
  }
}

void expect_within_fast_bound(const Geometry& geometry, const std::vector<Ray>& rays, const std::vector<Hit>& hits,
                              Query query, const std::vector<Hit>& references, const std::string& what) {
  AnswerErrors e = answer_errors(geometry, rays, hits, query, references);
  std::printf("[fast] %s: %zu leak(s) of %zu reference hits (%.1f%%), %zu false hit(s) of %zu, max t error %.3g ulps, "
              "max (u, v) error %.3g ulps\n",
              what.c_str(), e.leaks, e.reference_hits, 100.0 * e.leak_fraction(), e.false_hits, e.hits,
              e.max_t_error_ulps, e.max_uv_error_ulps);
  EXPECT_LE(e.leak_fraction(), kFastMaxLeakFraction) << what << ": " << e.leaks << " leaks of " << e.reference_hits;
  EXPECT_EQ(e.false_hits, 0u) << what << ": hits the reference rejects";
  EXPECT_LE(e.max_t_error_ulps, kFastMaxTErrorUlps) << what;
  EXPECT_LE(e.max_uv_error_ulps, kFastMaxUvErrorUlps) << what;
}

void run_everywhere(const Geometry& geometry, const std::vector<Ray>& rays, const Check& check,
                    RunOptions options) {
  const Device& device = test_device();
  for (Precision level : test_precisions()) {
    AccelConfig config{level, {}, ScatteredSort::always};  // scattered calls: the sorted kernels
    // The fast level is held to its measured bound (everywhere.hpp) against
    // the reference's closest hits, computed once for all its calls.
    std::vector<Hit> references;
    if (level == Precision::fast && options.judge && options.fast_bound)
      references = reference_closest_all(geometry, rays);
    auto brute = make_accel(device, "brute", geometry, config);
    std::vector<Hit> brute_hits[2] = {run_query(*brute, rays, Query::closest), run_query(*brute, rays, Query::any)};
    for (const std::string& name : tested_structures()) {
      auto accel = name == "brute" ? nullptr : make_accel(device, name, geometry, config);
      std::vector<std::pair<Coherence, Query>> calls = {{Coherence::incoherent, Query::closest},
                                                        {Coherence::incoherent, Query::any}};
      if (accel && accel->rays_per_work_item(Coherence::coherent) != accel->rays_per_work_item(Coherence::incoherent))
        calls.insert(calls.end(), {{Coherence::coherent, Query::closest}, {Coherence::coherent, Query::any}});
      // The sort is the same at every level (RTCL_TRACE_ORDER changes the
      // ray's read and the hit's write only): checked at the default level.
      if (accel && accel->sorts(Coherence::scattered) && level == Precision::robust)
        calls.insert(calls.end(), {{Coherence::scattered, Query::closest}, {Coherence::scattered, Query::any}});
      for (auto [coherence, query] : calls) {
        const char* order = coherence == Coherence::coherent ? " coherent " : coherence == Coherence::scattered ? " scattered " : " ";
        std::string what = name + " " + std::string(precision_name(level)) + order + query_name(query) + " on " +
                           geometry.source;
        SCOPED_TRACE(what);
        const std::vector<Hit>& expected = brute_hits[query == Query::closest ? 0 : 1];
        std::vector<Hit> hits = accel ? run_query(*accel, rays, query, coherence) : expected;
        expect_at_level(level, options.fast_must_pass, what, [&] {
          std::size_t failures = 0;
          std::string first, first_failure;
          const std::size_t disagreements = disagreements_with_brute(rays, hits, expected, query, &first);
          std::vector<Ray> unjudged_rays;
          std::vector<Hit> unjudged_hits;
          for (std::size_t i = 0; i < rays.size(); ++i) {
            bool judged_already = !accel || (hits[i].prim == expected[i].prim && hits[i].t == expected[i].t &&
                                             hits[i].u == expected[i].u && hits[i].v == expected[i].v);
            if (options.judge && accel && !judged_already) {
              unjudged_rays.push_back(rays[i]);
              unjudged_hits.push_back(hits[i]);
            }
          }
          if (!unjudged_rays.empty()) {
            auto report = judge_all(geometry, unjudged_rays, unjudged_hits, query, &failures);
            if (!report.empty()) first_failure = report[0];
          }
          // fast builds each kernel with -cl-fast-relaxed-math: no bit-for-bit promise between structures
          if (level != Precision::fast)
            EXPECT_EQ(disagreements, 0u) << "disagreements with brute force of " << rays.size() << " rays; first: "
                                         << first;
          if (options.judge && !accel) {
            auto report = judge_all(geometry, rays, hits, query, &failures);
            if (!report.empty()) first_failure = report[0];
          }
          EXPECT_EQ(failures, 0u) << "answers the double-precision reference rejects; first: " << first_failure;
          if (check) check(name, query, hits);
        });
        if (!references.empty()) expect_within_fast_bound(geometry, rays, hits, query, references, what);
      }
    }
  }
  run_through_motion(geometry, rays, check, options);
}

}  // namespace rtcl::test::everywhere
