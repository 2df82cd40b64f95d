// Exact primitive/box overlap tests for spatial subdivisions (grid cells):
// a primitive is listed in a cell exactly when it meets the cell's closed box.
// Evaluated in double precision on float inputs; callers that need a
// conservative answer widen the box (see grid.cpp).
#pragma once

#include <glm/glm.hpp>

namespace rtcl {

// Separating-axis test of a triangle against an axis-aligned box given by its
// centre and half extents (Akenine-Moller 2001, "Fast 3D triangle-box overlap
// testing"): the 3 box normals, the triangle normal and the 9 edge cross
// products. Touching (a shared point on the boundary) counts as overlap.
bool triangle_box_overlap(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& center,
                          const glm::dvec3& half);

// Sphere (solid ball) against a box: the squared distance from the centre to
// the box is at most r^2 (Arvo 1990, "A simple method for box-sphere
// intersection testing"). Touching counts.
bool sphere_box_overlap(const glm::dvec3& sphere_center, double radius, const glm::dvec3& lower,
                        const glm::dvec3& upper);

}  // namespace rtcl
