// Two unit vectors completing a unit vector n to an orthonormal basis,
// without a branch on n's direction (Duff et al., "Building an Orthonormal
// Basis, Revisited", JCGT 2017); for glm::vec3 and glm::dvec3.
#pragma once

#include <cmath>

namespace rtcl {

template <class Vec3>
void orthonormal_basis(const Vec3& n, Vec3& t1, Vec3& t2) {
  using Real = typename Vec3::value_type;
  Real sign = std::copysign(Real(1), n.z);
  Real a = Real(-1) / (sign + n.z);
  Real b = n.x * n.y * a;
  t1 = Vec3(Real(1) + sign * n.x * n.x * a, sign * b, -sign * n.x);
  t2 = Vec3(b, sign + n.y * n.y * a, -n.y);
}

}  // namespace rtcl
