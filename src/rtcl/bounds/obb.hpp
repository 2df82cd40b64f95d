// Oriented bounding box (OBB; lecture, 非平行于坐标轴的包围盒: "usually
// approximated by an iterative algorithm").
//
// Fit: the start is the principal axes of the points' covariance (PCA of the
// point set itself, not of its convex hull: no hull is built, so dense
// regions pull the axes; the refinement below corrects that) and, as a
// second start, the world axes. Each start is refined, on the points that
// are extreme along 129 directions spread over the sphere (at most 258 of
// them; the final extents are taken over all points), by coordinate descent
// over rotations about its own three axes, with steps from 0.25 rad halved
// down to min_step_rad (default 1e-5 rad), accepting a rotation only when it
// lowers the box's surface area (the quantity a random ray's hit probability is proportional
// to, and well defined for flat inputs, where every box has volume 0). Of
// the two refined boxes and the AABB, measured on all points, the one with
// the smallest area is kept, so the OBB's area never exceeds the AABB's.
// Bounded: at most 64 sweeps per step size.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/bounds/bounds_layouts.hpp"

namespace rtcl {

struct Obb {
  glm::vec3 axis[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  // unit as float, orthogonal to ~1e-7
  // The box is { x : d_near[i] <= dot(axis[i], x) <= d_far[i] } with these
  // float axes (so it contains every point exactly; see kdop.hpp).
  float d_near[3] = {0, 0, 0}, d_far[3] = {0, 0, 0};
  float reach = 0.0f;

  glm::vec3 half_extent() const;
  glm::vec3 center() const;  // sum of axis[i] * slab midpoint (display; exact for orthonormal axes)
  double volume() const;     // product of the slab widths (world units^3)
  double area() const;       // 2 * sum of the face products (world units^2)
  SlabVolume record() const;
};

// Throws like check_points (point_input.hpp). One point or equal points give
// a box of zero extent along the world axes. A coarser min_step_rad trades
// fit for time (each halving of it adds one round of the descent).
Obb obb_of_points(const std::vector<glm::vec3>& points, const std::string& source, double min_step_rad = 1e-5);

}  // namespace rtcl
