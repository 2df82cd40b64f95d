// The linearised refraction transform (src/rtcl/beam/refraction.*) against
// exact refraction by Snell's law: exact for the ray it is built for, and
// for a beam of rays around it an error that grows with the incidence angle
// (lecture: the linearisation assumes near-normal incidence).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "rtcl/beam/refraction.hpp"
#include "rtcl/error.hpp"

namespace rtcl::test {
namespace {

using glm::dvec3;
using glm::dvec4;

// Snell's law for unit d through the interface of unit normal n (n . d > 0),
// eta = n1 / n2.
dvec3 refract(dvec3 d, dvec3 n, double eta) {
  double c1 = glm::dot(n, d);
  dvec3 tangential = d - c1 * n;
  dvec3 t = eta * tangential;
  return t + std::sqrt(1.0 - glm::dot(t, t)) * n;
}

// Largest error |M_t P_t - P| / depth over a beam from an eye at unit
// distance, through a square of half-width `half` on the plane z = 0 around
// the point where the central ray of incidence angle theta meets it; P_t at
// depth `depth` on each exactly refracted ray, P on the same ray's straight
// continuation at that depth (where the virtual image must be).
double beam_error(double theta, double half, double eta, double depth = 1.0) {
  const dvec3 n(0.0, 0.0, -1.0);         // along the incident direction
  const dvec4 plane(0.0, 0.0, -1.0, 0.0);  // L . P = -z: > 0 in the medium entered
  dvec3 central(std::sin(theta), 0.0, -std::cos(theta));
  dvec3 eye = -central;
  glm::dmat4 m = *beam::refraction_matrix(plane, central, eta);
  double worst = 0.0;
  for (int i = -4; i <= 4; ++i)
    for (int j = -4; j <= 4; ++j) {
      dvec3 q(half * i / 4.0, half * j / 4.0, 0.0);
      dvec3 d = glm::normalize(q - eye);
      dvec3 t = refract(d, n, eta);
      dvec3 pt = q + (depth / glm::dot(n, t)) * t;
      dvec3 want = q + (depth / glm::dot(n, d)) * d;
      dvec3 got = dvec3(m * dvec4(pt, 1.0));
      worst = std::max(worst, glm::length(got - want) / depth);
    }
  return worst;
}

TEST(BeamRefraction, ExactForItsOwnRay) {
  for (double deg : {0.0, 15.0, 40.0, 70.0}) {
    double theta = deg * std::numbers::pi / 180.0;
    EXPECT_LT(beam_error(theta, 0.0, 1.0 / 1.5), 1e-12) << deg;
  }
}

TEST(BeamRefraction, ErrorGrowsWithIncidenceAngle) {
  // Air into glass; a beam of half-width 0.05 at unit distance (about 2.9
  // degrees either side of its central ray).
  std::vector<double> errors;
  for (double deg : {0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0}) {
    double e = beam_error(deg * std::numbers::pi / 180.0, 0.05, 1.0 / 1.5);
    std::printf("incidence %2.0f deg: largest error %.2e of the depth\n", deg, e);
    errors.push_back(e);
  }
  for (std::size_t i = 1; i < errors.size(); ++i) EXPECT_GT(errors[i], errors[i - 1]) << i;
  // At normal incidence M = 0 and the map is the identity: a ray of the
  // beam at angle phi is off by tan phi - tan phi2 (closed form; the beam's
  // corner ray has tan phi = 0.05 sqrt 2), the depth compression the
  // single-ray linearisation leaves out. At grazing angles tan is far from
  // linear across the beam's angles: several times looser.
  double tan1 = 0.05 * std::sqrt(2.0), sin2 = (1.0 / 1.5) * tan1 / std::sqrt(1.0 + tan1 * tan1);
  EXPECT_NEAR(errors.front(), tan1 - sin2 / std::sqrt(1.0 - sin2 * sin2), 1e-9);
  EXPECT_GT(errors.back(), 5.0 * errors.front());
  // A narrower beam is tighter at every angle (the error is the spread of
  // incidence angles times the curvature of tan).
  for (double deg : {10.0, 40.0, 70.0})
    EXPECT_LT(beam_error(deg * std::numbers::pi / 180.0, 0.01, 1.0 / 1.5),
              beam_error(deg * std::numbers::pi / 180.0, 0.05, 1.0 / 1.5));
}

TEST(BeamRefraction, TotalInternalReflectionAndBadInput) {
  const dvec4 plane(0.0, 0.0, 1.0, 0.0);
  // Glass to air: critical angle asin(1 / 1.5) = 41.8 degrees.
  auto at = [](double deg) { return dvec3(std::sin(deg * std::numbers::pi / 180.0), 0.0, std::cos(deg * std::numbers::pi / 180.0)); };
  EXPECT_TRUE(beam::refraction_matrix(plane, at(41.0), 1.5).has_value());
  EXPECT_FALSE(beam::refraction_matrix(plane, at(42.5), 1.5).has_value());
  // Normal incidence: the identity (M = 0).
  glm::dmat4 m = *beam::refraction_matrix(plane, at(0.0), 1.0 / 1.5);
  EXPECT_EQ(m, glm::dmat4(1.0));
  // The plane's orientation does not matter.
  EXPECT_EQ(*beam::refraction_matrix(plane, at(30.0), 1.0 / 1.5), *beam::refraction_matrix(-plane, at(30.0), 1.0 / 1.5));
  EXPECT_THROW(beam::refraction_matrix(dvec4(0.0), at(10.0), 1.5), Error);
  EXPECT_THROW(beam::refraction_matrix(plane, dvec3(0.0), 1.5), Error);
  EXPECT_THROW(beam::refraction_matrix(plane, dvec3(1.0, 0.0, 0.0), 1.5), Error);
  EXPECT_THROW(beam::refraction_matrix(plane, at(10.0), 0.0), Error);
}

}  // namespace
}  // namespace rtcl::test
