// The linearised refraction transform of beam tracing (Heckbert and
// Hanrahan 1984; lecture, 折射光线的变换): refraction bends straight lines
// into curves, so it is not a projective map; near normal incidence a point
// P_t on a refracted ray is moved to where the incident ray's straight
// continuation reaches the same depth,
//   P = P_t + alpha (L . P_t) M,   M = I - (N . I) N,   |M| = sin theta1,
//   alpha = (tan theta1 - tan theta2) / sin theta1,
// i.e. P = M_t P_t with M_t = E + alpha M L^T. Exact for the rays of
// incidence angle theta1 in the plane of incidence; for the other rays of a
// beam the error grows with theta1 (tan is linear only near 0). The beam
// renderer builds one M_t per refracted beam from its central ray
// (beam_renderer.hpp).
#pragma once

#include <optional>

#include <glm/glm.hpp>

namespace rtcl::beam {

// M_t for the interface plane L (normalised here; its normal is oriented
// along the incident direction, N . I > 0, so L . P > 0 in the medium the
// ray enters), the incident direction (normalised here) and eta = n1 / n2.
// None under total internal reflection (eta sin theta1 > 1). Throws Error for
// a zero normal or direction, a direction in the plane, or eta <= 0.
std::optional<glm::dmat4> refraction_matrix(const glm::dvec4& plane, const glm::dvec3& incident, double eta);

// Unpolarised Fresnel reflectance of a dielectric interface, eta = n1 / n2,
// the cosines of the incident and transmitted angles (both > 0): the ray
// tracer's (kernels/render/shade.cl), in double.
double fresnel_dielectric(double cos_i, double cos_t, double eta);

}  // namespace rtcl::beam
