// A simple polygon (concave allowed, no self-intersections) as a Region of
// triangles, by ear clipping: how concave beams and polygons enter the
// convex-piece representation of polygon2d.hpp.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/beam/polygon2d.hpp"

namespace rtcl::beam {

// Triangles with disjoint interiors whose union is the polygon (either
// orientation; collinear and repeated vertices allowed, they give no
// triangle). Throws Error naming `what` when the polygon has fewer than 3
// distinct vertices, zero area, or no ear can be cut (it is not simple).
Region triangulate(const std::vector<glm::dvec2>& polygon, const std::string& what = "polygon");

}  // namespace rtcl::beam
