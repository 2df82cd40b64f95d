// The input every bounding-volume builder shares: a point set, its checks,
// and outward rounding of double results to float.
//
// Degenerate input (docs/robustness.md): an empty set and a NaN or
// infinite coordinate are errors (rtcl::Error naming the source and, for a
// bad coordinate, the point's index); one point, equal points, collinear and
// coplanar points are valid and give volumes with zero extent along the
// missing dimensions.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/geometry.hpp"

namespace rtcl {

// Throws Error("SOURCE: no points to bound") or
// Error("SOURCE: point I has a non-finite coordinate (x, y, z)").
void check_points(const std::vector<glm::vec3>& points, const std::string& source);

// The vertices that some triangle uses, in vertex order, plus nothing for
// spheres (callers bound those in closed form). Throws like check_points
// when there are none.
std::vector<glm::vec3> used_vertices(const Geometry& geometry);

// max |p| (Euclidean) over the points, rounded up to float: the `reach` of
// the shared volume records.
float reach_of(const std::vector<glm::vec3>& points);

// The largest float <= x and the smallest float >= x.
float round_down(double x);
float round_up(double x);

}  // namespace rtcl
