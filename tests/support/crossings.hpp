// Double-precision brute force for the crossing queries (Accel::count,
// Accel::all_hits): every primitive the ray meets within [tmin, tmax],
// sorted by t, with a flag for rays the float answer may decide either way
// (a primitive within the scene's spatial tolerance of the ray, or a t
// within tolerance of tmin or tmax).
#pragma once

#include <cstdint>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/geometry.hpp"

namespace rtcl::test {

struct ReferenceCrossing {
  double t = 0.0;
  std::int32_t prim = -1;
};

struct ReferenceCrossings {
  std::vector<ReferenceCrossing> hits;  // the clear ones, sorted by t (ties: smaller prim)
  bool ambiguous = false;               // some primitive near the ray's boundary cases
  double t_tolerance = 0.0;             // ray parameter units (tolerance_in)
};

// All crossings of one ray; `bounds` = geometry.bounds() (computed once).
// Zero-area triangles are skipped (no structure stores them); a sphere
// gives both roots.
ReferenceCrossings reference_crossings(const Geometry& geometry, const Aabb& bounds, const Ray& ray);

// The same for every ray (on every hardware thread).
std::vector<ReferenceCrossings> reference_crossings_all(const Geometry& geometry, const std::vector<Ray>& rays);

}  // namespace rtcl::test
