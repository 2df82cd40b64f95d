// Every bounding volume of one point set, with its size and build time: what
// `rtcl bounds` prints and the bounds benchmark tabulates.
#pragma once

#include <string>
#include <vector>

#include "rtcl/bounds/bounds_layouts.hpp"
#include "rtcl/bounds/kdop.hpp"
#include "rtcl/bounds/obb.hpp"
#include "rtcl/bounds/sphere_bounds.hpp"

namespace rtcl {

struct BoundEntry {
  std::string name;  // "aabb", "obb", "kdop4", ..., "ritter", "iterated", "exact"
  bool sphere = false;
  SlabVolume slabs{};    // when !sphere
  SphereVolume ball{};   // when sphere
  double volume = 0.0;   // world units^3
  double area = 0.0;     // world units^2
  double build_ms = 0.0; // wall time of the builder alone (host clock)
};

struct BoundsReport {
  std::size_t point_count = 0;
  std::vector<BoundEntry> entries;  // the order of the names above; [0] is the AABB
  Obb obb;                          // entries "obb" as built (axes, extents)
  BoundingSphere ritter, iterated, exact;

  const BoundEntry& aabb() const { return entries.front(); }
};

// Throws like check_points (point_input.hpp).
BoundsReport report_bounds(const std::vector<glm::vec3>& points, const std::string& source);

}  // namespace rtcl
