// The reflection transform of beam tracing (lecture, 反射光线的变换): for a
// mirror plane L = (A, B, C, D), A^2 + B^2 + C^2 = 1, the virtual image of a
// point P_r is P = P_r - 2 (L . P_r) N = M_r P_r with N = (A, B, C, 0), i.e.
// the homogeneous 4x4 M_r = I - 2 N L^T. Tracing a reflected beam is tracing
// the scene transformed by M_r, seen through the mirror fragment.
#pragma once

#include <glm/glm.hpp>

namespace rtcl::beam {

// The plane through a, b, c as (A, B, C, D) with a unit normal along
// (b - a) x (c - a). Throws Error when the three points are collinear.
glm::dvec4 plane_through(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);

// M_r for a plane (normalised here). Throws Error for a zero normal.
glm::dmat4 reflection_matrix(const glm::dvec4& plane);

}  // namespace rtcl::beam
