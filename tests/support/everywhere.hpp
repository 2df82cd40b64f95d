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

std::string describe(const Ray& r);
std::string describe(const Hit& h);
const char* query_name(Query q);

// How many of `hits` differ from brute force's answers `brute` at the same
// level (hit or miss; a closest hit's t bit for bit), with the first of
// them described in *first.
std::size_t disagreements_with_brute(const std::vector<Ray>& rays, const std::vector<Hit>& hits,
                                     const std::vector<Hit>& brute, Query query, std::string* first);

// What a test checks beyond brute-force agreement, per accel and query (the
// level is the one expect_at_level runs it for).
using Check = std::function<void(const std::string& accel, Query query, const std::vector<Hit>& hits)>;

struct RunOptions {
  bool judge = true;            // also compare with the double-precision reference
  bool fast_must_pass = false;  // the check holds at the fast level too (else it is only reported there)
  // the fast level's answers are held to its bound below (with judge); false
  // only where the level promises none (needles and slivers)
  bool fast_bound = true;
  // every ray starts inside a closed mesh or crosses one within its
  // interval, so it hits wherever the geometry is placed: the motion pass
  // (run_through_motion) holds its rays in every world to that
  bool every_ray_hits = false;
  // the motion pass judges the rays in the worlds of its other times too;
  // false where they lie in or graze face planes by construction: there
  // the rounding of a moved instance's object ray (its documented error,
  // docs/scenes-and-instances.md, "Precision") decides hit or miss, and
  // the pass judges them at its identity time alone
  bool judge_moved = true;
};

// The fast level's bound (docs/precision.md: the measured maxima), over
// every call of every structure in the registry-wide suites (degenerate
// triangles aside: RunOptions::fast_bound), with margin: the share of the
// rays the reference clearly hits that go through (a miss, or a farther
// hit), no hit the judge rejects, and the largest error of t and of the
// (u, v) hit point in units of FLT_EPSILON x the scene's magnitude
// (reference.hpp: AnswerErrors).
constexpr double kFastMaxLeakFraction = 0.25;
constexpr double kFastMaxTErrorUlps = 128.0;
constexpr double kFastMaxUvErrorUlps = 128.0;

// Every answer of one call at the fast level within the bound above, the
// errors printed ("[fast] ..."); references[i] = reference_closest(rays[i]).
void expect_within_fast_bound(const Geometry& geometry, const std::vector<Ray>& rays, const std::vector<Hit>& hits,
                              Query query, const std::vector<Hit>& references, const std::string& what);

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
// reference judge (primitive, t and (u, v)), and pass `check`. At the fast
// level the judge's and the check's failures are printed
// (expect_at_level) and every answer is held to the level's bound
// (expect_within_fast_bound). The judge's verdict depends only on the answer, so
// brute force's answers are judged in full and another structure's only
// where they differ (same t, another primitive sharing an edge or vertex).
// Then the same rays go through moving instances (run_through_motion).
void run_everywhere(const Geometry& geometry, const std::vector<Ray>& rays, const Check& check,
                    RunOptions options = {});

// The motion pass: the geometry as the mesh of two coincident two-keyframe
// instances (rtcl::Scene, the BVH bottom level, through the top level),
// whose blended transform is exactly the identity at time 0.5 and turns,
// shears, scales and moves the mesh at 0, 0.25, 0.75 and 1 (a uniform
// scale and a move for a geometry with spheres). At every level and both
// queries: the rays at time 0.5 pass the judge on the geometry and
// `check`; each ray placed in the world of one of the other times (its
// origin and direction mapped in double, the interval kept), traced at
// that time, passes the judge on the geometry placed at that time (the
// reference of the scene interpolated at the ray's time; with
// judge_moved), and with every_ray_hits hits. The fast level as
// run_everywhere treats it.
void run_through_motion(const Geometry& geometry, const std::vector<Ray>& rays, const Check& check,
                        const RunOptions& options);

}  // namespace rtcl::test::everywhere
