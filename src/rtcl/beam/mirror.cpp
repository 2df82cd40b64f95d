#include "rtcl/beam/mirror.hpp"

#include <cmath>

#include "rtcl/error.hpp"

namespace rtcl::beam {

glm::dvec4 plane_through(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  glm::dvec3 e1 = b - a, e2 = c - a;
  double scale = std::max(glm::length(e1), glm::length(e2));
  if (!(scale > 0.0)) throw Error("beam: mirror plane through coincident points");
  glm::dvec3 n = glm::cross(e1 / scale, e2 / scale);  // scaled first: no under/overflow at any scene scale
  double len = glm::length(n);
  if (!(len > 0.0)) throw Error("beam: mirror plane through collinear points");
  n /= len;
  return {n, -glm::dot(n, a)};
}

glm::dmat4 reflection_matrix(const glm::dvec4& plane) {
  double len = glm::length(glm::dvec3(plane));
  if (!(len > 0.0) || !std::isfinite(len)) throw Error("beam: mirror plane with a zero or non-finite normal");
  glm::dvec4 L = plane / len;
  glm::dvec4 N(L.x, L.y, L.z, 0.0);
  glm::dmat4 m(1.0);
  // glm is column-major: m[col][row]; M_r[row][col] = delta - 2 N[row] L[col].
  for (int col = 0; col < 4; ++col)
    for (int row = 0; row < 4; ++row) m[col][row] -= 2.0 * N[row] * L[col];
  return m;
}

}  // namespace rtcl::beam
