// A triangle clipped to an axis-aligned box: the bounds of the part of the
// triangle inside the box, for "perfect splits" in kd-tree construction
// (Havran 2000, section 4.5; Wald & Havran 2006, section 4.3) and for
// deciding which halves of a BSP node a triangle reaches.
#pragma once

#include <glm/glm.hpp>

namespace rtcl {

// Clips triangle (a, b, c) to the closed box [lower, upper] (Sutherland-
// Hodgman against the six planes, in double) and returns the bounds of what
// is left in [*out_lower, *out_upper], intersected with the box; false when
// nothing is left. A triangle touching the box in a point or an edge keeps
// that point or edge. The bounds are those of the double-precision polygon:
// callers that need a conservative answer widen the box.
bool clip_triangle_bounds(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& lower,
                          const glm::dvec3& upper, glm::dvec3* out_lower, glm::dvec3* out_upper);

// The same for the two children of [lower, upper] split on `axis`: the
// part of the triangle in [lower, upper] with x[axis] <= below_upper
// (below) and with x[axis] >= above_lower (above), each bounded by its
// child box. The triangle is clipped to the parent box once and that
// polygon by each child's plane, which halves the work of clipping to both
// children; the bounds agree with clip_triangle_bounds' to its rounding.
struct ClipSplit {
  bool below = false, above = false;  // whether anything is left
  glm::dvec3 below_lower{0.0}, below_upper{0.0}, above_lower{0.0}, above_upper{0.0};
};
ClipSplit clip_triangle_split(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& lower,
                              const glm::dvec3& upper, int axis, double below_upper, double above_lower);

}  // namespace rtcl
