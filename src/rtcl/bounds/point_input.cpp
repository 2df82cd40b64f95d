#include "rtcl/bounds/point_input.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "rtcl/error.hpp"

namespace rtcl {

void check_points(const std::vector<glm::vec3>& points, const std::string& source) {
  if (points.empty()) throw Error(source + ": no points to bound");
  for (std::size_t i = 0; i < points.size(); ++i) {
    const glm::vec3& p = points[i];
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) continue;
    char text[160];
    std::snprintf(text, sizeof text, ": point %zu has a non-finite coordinate (%g, %g, %g)", i, p.x, p.y, p.z);
    throw Error(source + text);
  }
}

std::vector<glm::vec3> used_vertices(const Geometry& geometry) {
  std::vector<char> used(geometry.vertices.size(), 0);
  for (const glm::uvec3& t : geometry.triangles)
    for (int k = 0; k < 3; ++k)
      if (t[k] < used.size()) used[t[k]] = 1;
  std::vector<glm::vec3> points;
  for (std::size_t i = 0; i < used.size(); ++i)
    if (used[i]) points.push_back(geometry.vertices[i]);
  check_points(points, geometry.source);
  return points;
}

float reach_of(const std::vector<glm::vec3>& points) {
  double r = 0.0;
  for (const glm::vec3& p : points) r = std::fmax(r, glm::length(glm::dvec3(p)));
  return round_up(r);
}

float round_down(double x) {
  float f = static_cast<float>(x);
  return static_cast<double>(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}

float round_up(double x) {
  float f = static_cast<float>(x);
  return static_cast<double>(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

}  // namespace rtcl
