#include "rtcl/bounds/overlap.hpp"

#include <algorithm>
#include <cmath>

namespace rtcl {

namespace {

// True when the projections of the triangle (vertices relative to the box
// centre) and of the box on `axis` are disjoint: a separating axis.
bool separated(const glm::dvec3& axis, const glm::dvec3& v0, const glm::dvec3& v1, const glm::dvec3& v2,
               const glm::dvec3& half) {
  double p0 = glm::dot(axis, v0), p1 = glm::dot(axis, v1), p2 = glm::dot(axis, v2);
  double r = half.x * std::fabs(axis.x) + half.y * std::fabs(axis.y) + half.z * std::fabs(axis.z);
  return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
}

}  // namespace

bool triangle_box_overlap(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& center,
                          const glm::dvec3& half) {
  glm::dvec3 v0 = a - center, v1 = b - center, v2 = c - center;
  // The box normals: the triangle's bounding box against the box.
  for (int k = 0; k < 3; ++k)
    if (std::min({v0[k], v1[k], v2[k]}) > half[k] || std::max({v0[k], v1[k], v2[k]}) < -half[k]) return false;
  const glm::dvec3 edges[3] = {v1 - v0, v2 - v1, v0 - v2};
  // The plane of the triangle (a zero normal of a degenerate triangle
  // separates nothing: r = 0 and the projections are all 0).
  glm::dvec3 n = glm::cross(edges[0], edges[1]);
  if (separated(n, v0, v1, v2, half)) return false;
  // The nine cross products of box axes and triangle edges.
  for (const glm::dvec3& e : edges) {
    if (separated(glm::dvec3(0.0, -e.z, e.y), v0, v1, v2, half)) return false;
    if (separated(glm::dvec3(e.z, 0.0, -e.x), v0, v1, v2, half)) return false;
    if (separated(glm::dvec3(-e.y, e.x, 0.0), v0, v1, v2, half)) return false;
  }
  return true;
}

bool sphere_box_overlap(const glm::dvec3& sphere_center, double radius, const glm::dvec3& lower,
                        const glm::dvec3& upper) {
  glm::dvec3 nearest = glm::clamp(sphere_center, lower, upper);
  glm::dvec3 d = sphere_center - nearest;
  return glm::dot(d, d) <= radius * radius;
}

}  // namespace rtcl
