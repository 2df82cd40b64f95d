// The one driver of the adversarial suites: every structure of the
// registry, at every precision level, both queries, both kernels, checked
// against brute force at the same level, the double-precision reference and
// a test's own expectation. New structures and levels are covered with no
// new test code.
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/layouts.hpp"

namespace rtcl::test::everywhere {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

Ray make_ray(glm::vec3 o, glm::vec3 d, float tmin = 0.0f, float tmax = kInf);
std::string describe(const Ray& r);
std::string describe(const Hit& h);
const char* query_name(Query q);

// What a test checks beyond brute-force agreement, per accel and query (the
// level is the one expect_at_level runs it for).
using Check = std::function<void(const std::string& accel, Query query, const std::vector<Hit>& hits)>;

struct RunOptions {
  bool judge = true;            // also compare with the double-precision reference
  bool fast_must_pass = false;  // the check holds at the fast level too (else it is only reported there)
};

// Runs `evaluate`; at the fast level (not watertight, no conservative slabs)
// unless `must_pass`, its failed expectations are counted and printed
// ("[fast] ...") instead of failing the test: that is the level's
// documented trade.
void expect_at_level(Precision level, bool must_pass, const std::string& what, const std::function<void()>& evaluate);

// Runs both queries of every structure at every precision level on the
// rays, and again as a Coherence::coherent call where that selects another
// kernel (the answers may not depend on the promise); each answer must
// agree with brute force at the same level bit for bit (robust and exact;
// fast builds with -cl-fast-relaxed-math, no such promise), pass the
// reference judge, and pass `check` (at the fast level see
// expect_at_level). The judge's verdict depends only on the answer, so
// brute force's answers are judged in full and another structure's only
// where they differ (same t, another primitive sharing an edge or vertex).
void run_everywhere(const Geometry& geometry, const std::vector<Ray>& rays, const Check& check,
                    RunOptions options = {});

}  // namespace rtcl::test::everywhere
