#include "rtcl/accel/bvh_presplit.hpp"

#include <cfloat>
#include <cmath>

namespace rtcl {

namespace {

// The box of the part of triangle v on one side of the plane
// coordinate[axis] = plane (the lower side when `lower`), within `within`:
// the triangle's vertices on that side (the plane included) and the points
// where its edges cross the plane. A crossing point's other coordinates
// carry the rounding of a + s (b - a): they are widened by 4 ulps of the
// operands' magnitudes, so that the box holds the exact part.
Aabb side_box(const glm::vec3 (&v)[3], const Aabb& within, int axis, float plane, bool lower) {
  Aabb box;
  for (int i = 0; i < 3; ++i) {
    const glm::vec3 &a = v[i], &b = v[(i + 1) % 3];
    const bool a_in = lower ? a[axis] <= plane : a[axis] >= plane;
    const bool b_in = lower ? b[axis] <= plane : b[axis] >= plane;
    if (a_in) box.grow(a);
    if (a_in == b_in) continue;
    const float s = (plane - a[axis]) / (b[axis] - a[axis]);
    glm::vec3 lo = a + s * (b - a), hi = lo;
    for (int k = 0; k < 3; ++k) {
      const float widen = 4.0f * FLT_EPSILON * (std::fabs(a[k]) + std::fabs(b[k]));
      lo[k] -= widen;
      hi[k] += widen;
    }
    lo[axis] = hi[axis] = plane;
    box.grow(lo);
    box.grow(hi);
  }
  box.lower = glm::max(box.lower, within.lower);
  box.upper = glm::min(box.upper, within.upper);
  return box;
}

int longest_axis(const glm::vec3& e) { return e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2); }

}  // namespace

std::size_t presplit_triangles(const Geometry& geometry, std::vector<std::uint32_t>& ids, std::vector<Aabb>& bounds,
                               std::size_t triangle_refs, float factor) {
  if (!(factor > 0.0f) || triangle_refs == 0) return triangle_refs;
  double area_sum = 0.0;
  for (std::size_t i = 0; i < triangle_refs; ++i) area_sum += bounds[i].area();
  const float threshold = static_cast<float>(factor * area_sum / static_cast<double>(triangle_refs));

  // A split reference keeps its slot for its first part; the other parts
  // follow the triangle references, in the order of their triangles.
  const std::size_t budget = kPresplitMaxGrowth * triangle_refs;
  std::vector<std::uint32_t> more_ids;
  std::vector<Aabb> more_bounds;
  struct Part {
    Aabb box;
    int depth;
  };
  std::vector<Part> parts;
  for (std::size_t i = 0; i < triangle_refs; ++i) {
    if (!(bounds[i].area() > threshold) || triangle_refs + more_ids.size() + 1 > budget) continue;
    const glm::uvec3& t = geometry.triangles[ids[i]];
    const glm::vec3 v[3] = {geometry.vertices[t.x], geometry.vertices[t.y], geometry.vertices[t.z]};
    bool first = true;
    parts.assign(1, Part{bounds[i], 0});
    while (!parts.empty()) {
      const Part part = parts.back();
      parts.pop_back();
      const glm::vec3 extent = part.box.extent();
      const int axis = longest_axis(extent);
      const float plane = part.box.lower[axis] + 0.5f * extent[axis];
      // The references if this part and the pending ones were kept (the
      // first of them takes slot i), plus the one a split adds.
      const std::size_t kept = triangle_refs + more_ids.size() + parts.size() + (first ? 0 : 1);
      const bool split = part.box.area() > threshold && part.depth < kPresplitMaxDepth &&
                         plane > part.box.lower[axis] && plane < part.box.upper[axis] && kept + 1 <= budget;
      if (!split) {
        if (first) {
          bounds[i] = part.box;
          first = false;
        } else {
          more_ids.push_back(ids[i]);
          more_bounds.push_back(part.box);
        }
        continue;
      }
      const Aabb below = side_box(v, part.box, axis, plane, true);
      const Aabb above = side_box(v, part.box, axis, plane, false);
      // A side that only touches the plane is held by the other side too.
      const bool below_flat = below.empty() || below.lower[axis] == below.upper[axis];
      const bool above_flat = above.empty() || above.lower[axis] == above.upper[axis];
      if (!above.empty() && !(above_flat && !below_flat)) parts.push_back({above, part.depth + 1});
      if (!below.empty() && !(below_flat && !above_flat)) parts.push_back({below, part.depth + 1});
    }
  }
  const auto at = static_cast<std::ptrdiff_t>(triangle_refs);
  ids.insert(ids.begin() + at, more_ids.begin(), more_ids.end());
  bounds.insert(bounds.begin() + at, more_bounds.begin(), more_bounds.end());
  return triangle_refs + more_ids.size();
}

}  // namespace rtcl
