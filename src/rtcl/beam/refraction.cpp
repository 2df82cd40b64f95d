#include "rtcl/beam/refraction.hpp"

#include <cmath>

#include "rtcl/error.hpp"

namespace rtcl::beam {

std::optional<glm::dmat4> refraction_matrix(const glm::dvec4& plane, const glm::dvec3& incident, double eta) {
  double nl = glm::length(glm::dvec3(plane)), il = glm::length(incident);
  if (!(nl > 0.0) || !std::isfinite(nl)) throw Error("beam: refraction plane with a zero or non-finite normal");
  if (!(il > 0.0) || !std::isfinite(il)) throw Error("beam: refraction with a zero or non-finite direction");
  if (!(eta > 0.0) || !std::isfinite(eta)) throw Error("beam: refraction with eta <= 0");
  glm::dvec4 L = plane / nl;
  glm::dvec3 N(L), I = incident / il;
  double cos1 = glm::dot(N, I);
  if (cos1 < 0.0) {  // orient the plane along the incident direction
    L = -L;
    N = -N;
    cos1 = -cos1;
  }
  if (!(cos1 > 0.0)) throw Error("beam: refraction of a direction in the interface plane");
  glm::dvec3 M = I - cos1 * N;
  double sin1 = std::min(1.0, glm::length(M));
  double sin2 = eta * sin1;
  if (sin2 > 1.0) return std::nullopt;
  double cos2 = std::sqrt(1.0 - sin2 * sin2);
  // alpha -> 1 - eta at normal incidence, where M = 0 anyway.
  double alpha = sin1 > 0.0 ? (sin1 / cos1 - sin2 / cos2) / sin1 : 1.0 - eta;
  glm::dmat4 m(1.0);
  const glm::dvec4 M4(M, 0.0);
  for (int col = 0; col < 4; ++col)
    for (int row = 0; row < 4; ++row) m[col][row] += alpha * M4[row] * L[col];
  return m;
}

double fresnel_dielectric(double cos_i, double cos_t, double eta) {
  const double rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  const double rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

}  // namespace rtcl::beam
