// Axis-aligned bounding box (lecture: AABB from per-axis min/max of vertices).
#pragma once

#include <glm/glm.hpp>
#include <limits>

namespace rtcl {

struct Aabb {
  glm::vec3 lower{std::numeric_limits<float>::infinity()};
  glm::vec3 upper{-std::numeric_limits<float>::infinity()};

  bool empty() const { return lower.x > upper.x || lower.y > upper.y || lower.z > upper.z; }
  void grow(const glm::vec3& p) {
    lower = glm::min(lower, p);
    upper = glm::max(upper, p);
  }
  void grow(const Aabb& b) {
    lower = glm::min(lower, b.lower);
    upper = glm::max(upper, b.upper);
  }
  // Closed containment: every coordinate of the point / box within this one.
  bool contains(const glm::vec3& p) const {
    return glm::all(glm::lessThanEqual(lower, p)) && glm::all(glm::lessThanEqual(p, upper));
  }
  bool contains(const Aabb& b) const {
    return glm::all(glm::lessThanEqual(lower, b.lower)) && glm::all(glm::greaterThanEqual(upper, b.upper));
  }
  glm::vec3 extent() const { return upper - lower; }
  glm::vec3 center() const { return 0.5f * (lower + upper); }
  // Surface area; 0 for an empty box (SAH cost unit).
  float area() const {
    if (empty()) return 0.0f;
    glm::vec3 e = extent();
    return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
  }
};

inline Aabb merge(Aabb a, const Aabb& b) {
  a.grow(b);
  return a;
}

}  // namespace rtcl
