// Double-precision host reference for every query, and the rule that decides
// whether a device answer is right. Tolerances scale with the scene: a hit is
// "clear" when the ray passes inside the primitive by more than the spatial
// tolerance, "ambiguous" near its boundary, where either answer is accepted.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/layouts.hpp"
#include "rtcl/geometry.hpp"

namespace rtcl::test {

struct PrimHit {
  bool plane = false;   // the ray meets the primitive's surface (plane / sphere) at t
  double t = 0.0;
  double margin = 0.0;  // world units: > 0 inside the triangle (or sphere silhouette), < 0 outside
};

// Intersection with one primitive in double precision. For spheres, the
// nearest root with t >= tmin - tolerance is reported.
PrimHit reference_intersect(const Geometry& geometry, std::uint32_t prim, const Ray& ray);
struct Tolerance;
// The same with the ray's tolerance_for given (that costs a pass over the
// scene: compute it once per ray when testing every primitive).
PrimHit reference_intersect(const Geometry& geometry, std::uint32_t prim, const Ray& ray, const Tolerance& tolerance);

struct Tolerance {
  double space;  // world units
  double t;      // ray parameter units
};
// Scales with the scene's extent and the ray origin's magnitude, in units of
// float epsilon times `ulps`.
Tolerance tolerance_for(const Geometry& geometry, const Ray& ray, double ulps = 256.0);
// The same with the scene's bounds given (geometry.bounds(): a pass over
// every primitive, computed once where many rays are checked).
Tolerance tolerance_in(const Aabb& bounds, const Ray& ray, double ulps = 256.0);

// Nearest clear hit (t = +inf, prim = -1 when none) by brute force in double.
Hit reference_closest(const Geometry& geometry, const Ray& ray);

// "" when the device's answer is acceptable, else why not.
std::string judge(const Geometry& geometry, const Ray& ray, const Hit& device, Query query);

// Runs judge over all rays and returns up to `report` failure descriptions
// (and the total failure count in *failures).
std::vector<std::string> judge_all(const Geometry& geometry, const std::vector<Ray>& rays,
                                   const std::vector<Hit>& hits, Query query, std::size_t* failures,
                                   std::size_t report = 5);

// reference_closest for every ray. The reference is O(primitives) per ray:
// compute it once and pass it to the judge_all below when several answers
// (structures, queries) are judged for the same rays of a large scene.
std::vector<Hit> reference_closest_all(const Geometry& geometry, const std::vector<Ray>& rays);

// judge_all with references[i] == reference_closest(geometry, rays[i]).
std::vector<std::string> judge_all(const Geometry& geometry, const std::vector<Ray>& rays,
                                   const std::vector<Hit>& hits, Query query, const std::vector<Hit>& references,
                                   std::size_t* failures, std::size_t report = 5);

// The closest primitive by the double reference, or prim = -2 when double
// precision itself cannot tell: the hit, or another candidate as near in t,
// lies within 1e-9 of scene_size (at least 1e-12 of the coordinates'
// magnitude, tolerance_for's) of a primitive's boundary, or as near (over
// |d|) in t to tmin, tmax or the other's t. That is where the exact level
// must agree (docs/precision.md), far closer to the boundaries than the
// robust judge's tolerance (256 float ulps, ~3e-5). prim = -1 (t = +inf):
// double precision decides that the ray misses.
struct DoubleAnswer {
  int prim = -1;
  double t = 0.0;
};
DoubleAnswer double_closest(const Geometry& geometry, const Ray& ray, double scene_size);

// How far answers stray from the reference, for a level without the
// judge's guarantee (fast), against references[i] == reference_closest(
// geometry, rays[i]).
struct AnswerErrors {
  std::size_t reference_hits = 0;  // rays the reference clearly hits within [tmin, tmax]
  // of those, answered with a miss, or (closest) with a hit farther than the
  // reference's by more than the judge's t tolerance: the ray went through
  std::size_t leaks = 0;
  std::size_t hits = 0;        // answers that hit
  std::size_t false_hits = 0;  // hits the judge rejects: off the primitive, or t off its plane
  // Largest |t - the reference's t on the answer's primitive| over hits, in
  // units of the judge's scale (FLT_EPSILON x the scene and origin magnitude
  // / |d|; the judge accepts 256).
  double max_t_error_ulps = 0.0;
  // Largest distance between the point the answer's (u, v) describe and
  // the reference's hit point, in the same units times |d|.
  double max_uv_error_ulps = 0.0;
  double leak_fraction() const { return reference_hits ? double(leaks) / double(reference_hits) : 0.0; }
};
AnswerErrors answer_errors(const Geometry& geometry, const std::vector<Ray>& rays, const std::vector<Hit>& hits,
                           Query query, const std::vector<Hit>& references);

}  // namespace rtcl::test
