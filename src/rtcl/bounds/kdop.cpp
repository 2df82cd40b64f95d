#include "rtcl/bounds/kdop.hpp"

#include <cmath>
#include <limits>

#include "rtcl/bounds/point_input.hpp"
#include "rtcl/error.hpp"

namespace rtcl {

namespace {

std::vector<glm::dvec3> direction_set(int count) {
  const std::vector<glm::dvec3> axes = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const std::vector<glm::dvec3> corners = {{1, 1, 1}, {1, 1, -1}, {1, -1, 1}, {-1, 1, 1}};
  const std::vector<glm::dvec3> edges = {{1, 1, 0}, {1, -1, 0}, {1, 0, 1}, {1, 0, -1}, {0, 1, 1}, {0, 1, -1}};
  std::vector<glm::dvec3> out;
  auto add = [&](const std::vector<glm::dvec3>& set) {
    for (const glm::dvec3& d : set) out.push_back(glm::normalize(d));
  };
  switch (count) {
    case 3: add(axes); break;
    case 4: add(corners); break;
    case 7: add(axes); add(corners); break;
    case 9: add(axes); add(edges); break;
    case 13: add(axes); add(corners); add(edges); break;
    default: throw Error("k-DOP: unsupported direction count " + std::to_string(count) + " (supported: 3, 4, 7, 9, 13)");
  }
  return out;
}

Kdop empty_kdop(int count) {
  Kdop k;
  std::vector<glm::dvec3> dirs = direction_set(count);
  k.count = count;
  for (int i = 0; i < count; ++i) {
    k.normal[i] = glm::vec3(dirs[i]);
    k.d_near[i] = std::numeric_limits<float>::infinity();
    k.d_far[i] = -std::numeric_limits<float>::infinity();
  }
  return k;
}

// Extends slab i to [lo, hi] (double), rounding outward.
void grow_slab(Kdop& k, int i, double lo, double hi) {
  k.d_near[i] = std::fmin(k.d_near[i], round_down(lo));
  k.d_far[i] = std::fmax(k.d_far[i], round_up(hi));
}

void grow_points(Kdop& k, const std::vector<glm::vec3>& points) {
  for (int i = 0; i < k.count; ++i) {
    // The stored float normal defines the volume: project on it exactly (in
    // double, the products and sums of floats err by < 1e-16 relative; the
    // outward rounding to float is far coarser).
    glm::dvec3 n(k.normal[i]);
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const glm::vec3& p : points) {
      double d = glm::dot(n, glm::dvec3(p));
      lo = std::fmin(lo, d);
      hi = std::fmax(hi, d);
    }
    grow_slab(k, i, lo, hi);
  }
}

}  // namespace

SlabVolume slab_record(int count, const glm::vec3* normal, const float* d_near, const float* d_far, float reach) {
  SlabVolume v{};
  v.count = count;
  for (int i = 0; i < count; ++i) {
    v.normal[i][0] = normal[i].x;
    v.normal[i][1] = normal[i].y;
    v.normal[i][2] = normal[i].z;
    v.d_near[i] = d_near[i];
    v.d_far[i] = d_far[i];
  }
  v.reach = reach;
  return v;
}

SlabVolume Kdop::record() const { return slab_record(count, normal.data(), d_near.data(), d_far.data(), reach); }

const std::vector<int>& kdop_direction_counts() {
  static const std::vector<int> counts = {3, 4, 7, 9, 13};
  return counts;
}

std::vector<glm::vec3> kdop_directions(int count) {
  std::vector<glm::vec3> out;
  for (const glm::dvec3& d : direction_set(count)) out.push_back(glm::vec3(d));
  return out;
}

Kdop kdop_of_points(const std::vector<glm::vec3>& points, int count, const std::string& source) {
  check_points(points, source);
  Kdop k = empty_kdop(count);
  grow_points(k, points);
  k.reach = reach_of(points);
  return k;
}

Kdop kdop_of_geometry(const Geometry& geometry, int count) {
  Kdop k = empty_kdop(count);
  double reach = 0.0;
  if (!geometry.triangles.empty()) {
    std::vector<glm::vec3> points = used_vertices(geometry);
    grow_points(k, points);
    reach = reach_of(points);
  }
  for (std::size_t s = 0; s < geometry.spheres.size(); ++s) {
    const Sphere& sphere = geometry.spheres[s];
    glm::dvec3 c(sphere.center);
    double r = sphere.radius;
    if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z) || !(r >= 0.0) || !std::isfinite(r))
      throw Error(geometry.source + ": sphere " + std::to_string(s) + " has a non-finite centre or a bad radius");
    for (int i = 0; i < k.count; ++i) {
      glm::dvec3 n(k.normal[i]);
      double mid = glm::dot(n, c), half = r * glm::length(n);
      grow_slab(k, i, mid - half, mid + half);
    }
    reach = std::fmax(reach, glm::length(c) + r);
  }
  if (geometry.triangles.empty() && geometry.spheres.empty()) throw Error(geometry.source + ": no points to bound");
  k.reach = round_up(reach);
  return k;
}

}  // namespace rtcl
