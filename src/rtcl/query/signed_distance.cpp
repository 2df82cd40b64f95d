// Accel::signed_distance and Accel::occupancy (rtcl/accel.hpp): the
// closest point's distance, signed by ray parity. From each point, nsamples
// rays in fixed directions count their crossings of the surface
// (Accel::count, which counts a crossing through a shared edge or vertex
// once); an odd count is a vote for inside, and the majority decides, so
// that one ray grazing an edge or lying in a face plane cannot flip the
// sign (the nsamples of Open3D's RaycastingScene::compute_signed_distance).
#include <algorithm>
#include <cmath>
#include <string>

#include "rtcl/accel.hpp"
#include "rtcl/error.hpp"

namespace rtcl {

namespace {

// Direction k of n: a Fibonacci spiral over the sphere (Gonzalez 2010,
// "Measurement of areas on a sphere using Fibonacci and latitude-longitude
// lattices"), turned by a fixed rotation so that no direction is parallel
// to an axis or to a diagonal, whose planes meshes are often built on.
glm::vec3 vote_direction(unsigned k, unsigned n) {
  const double golden = 2.399963229728653;  // pi (3 - sqrt 5)
  const double z = 1.0 - (2.0 * k + 1.0) / n;
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  const double phi = golden * k + 0.4142135623730950;  // offset: sqrt 2 - 1
  glm::dvec3 d(r * std::cos(phi), r * std::sin(phi), z);
  // Rotation by 0.7 rad about x, then 0.3 rad about y.
  const double cx = std::cos(0.7), sx = std::sin(0.7), cy = std::cos(0.3), sy = std::sin(0.3);
  d = glm::dvec3(d.x, cx * d.y - sx * d.z, sx * d.y + cx * d.z);
  d = glm::dvec3(cy * d.x + sy * d.z, d.y, -sy * d.x + cy * d.z);
  return glm::vec3(d);
}

void check_nsamples(const char* call, unsigned nsamples) {
  if (nsamples == 0 || nsamples % 2 == 0)
    throw Error(std::string(call) + ": nsamples is " + std::to_string(nsamples) + ", must be odd (1, 3, 5, ...)");
}

// 1 where the majority of nsamples rays from the point cross the surface
// an odd number of times.
std::vector<std::uint8_t> inside_votes(const Accel& accel, const Points& points, unsigned nsamples) {
  const std::size_t n = points.size();
  std::vector<std::uint8_t> inside(n, 0);
  std::vector<glm::vec3> directions(nsamples);
  for (unsigned k = 0; k < nsamples; ++k) directions[k] = vote_direction(k, nsamples);
  // Points in chunks, so that the rays of one chunk stay about 1M.
  const std::size_t chunk = std::max<std::size_t>(1, (std::size_t{1} << 20) / nsamples);
  std::vector<Ray> rays;
  std::span<const float> xyz = points.xyz();
  for (std::size_t first = 0; first < n; first += chunk) {
    const std::size_t m = std::min(chunk, n - first);
    rays.resize(m * nsamples);
    for (std::size_t i = 0; i < m; ++i) {
      const float* p = xyz.data() + 3 * (first + i);
      for (unsigned k = 0; k < nsamples; ++k) {
        const glm::vec3& d = directions[k];
        rays[i * nsamples + k] = Ray{p[0], p[1], p[2], d.x, d.y, d.z, 0.0f, INFINITY};
      }
    }
    std::vector<std::uint32_t> counts = accel.count(rays);
    for (std::size_t i = 0; i < m; ++i) {
      unsigned odd = 0;
      for (unsigned k = 0; k < nsamples; ++k) odd += counts[i * nsamples + k] & 1u;
      inside[first + i] = 2 * odd > nsamples ? 1 : 0;
    }
  }
  return inside;
}

}  // namespace

std::vector<float> Accel::signed_distance(const Points& points, unsigned nsamples) const {
  check_nsamples("signed_distance", nsamples);
  std::vector<float> d = distance(points);  // checks the points
  std::vector<std::uint8_t> inside = inside_votes(*this, points, nsamples);
  for (std::size_t i = 0; i < d.size(); ++i)
    if (inside[i]) d[i] = -d[i];
  return d;
}

std::vector<std::uint8_t> Accel::occupancy(const Points& points, unsigned nsamples) const {
  check_nsamples("occupancy", nsamples);
  std::span<const float> xyz = points.xyz();
  for (std::size_t i = 0; i < xyz.size(); ++i)
    if (!std::isfinite(xyz[i]))
      throw Error("occupancy: points[" + std::to_string(i / 3) + "] has a NaN or infinite coordinate");
  return inside_votes(*this, points, nsamples);
}

}  // namespace rtcl
