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

}  // namespace rtcl
