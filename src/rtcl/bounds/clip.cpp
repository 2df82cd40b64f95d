#include "rtcl/bounds/clip.hpp"

#include <algorithm>

namespace rtcl {

bool clip_triangle_bounds(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& lower,
                          const glm::dvec3& upper, glm::dvec3* out_lower, glm::dvec3* out_upper) {
  // A convex polygon clipped by one plane gains at most one vertex: 3 + 6.
  constexpr int kMaxVertices = 9;
  glm::dvec3 buffers[2][kMaxVertices];
  glm::dvec3* poly = buffers[0];
  glm::dvec3* next = buffers[1];
  poly[0] = a, poly[1] = b, poly[2] = c;
  int n = 3;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      // Keep sign * (p[axis] - bound) >= 0.
      double bound = side == 0 ? lower[axis] : upper[axis];
      double sign = side == 0 ? 1.0 : -1.0;
      bool inside = true;
      for (int v = 0; v < n && inside; ++v) inside = sign * (poly[v][axis] - bound) >= 0.0;
      if (inside) continue;  // the plane keeps the polygon as it is
      int m = 0;
      for (int v = 0; v < n; ++v) {
        const glm::dvec3 &p = poly[v], &q = poly[v + 1 == n ? 0 : v + 1];
        double dp = sign * (p[axis] - bound), dq = sign * (q[axis] - bound);
        if (dp >= 0.0) next[m++] = p;
        if ((dp >= 0.0) != (dq >= 0.0) && m < kMaxVertices) {
          glm::dvec3 x = p + (q - p) * (dp / (dp - dq));
          x[axis] = bound;  // on the plane, whatever the rounding of the interpolation
          next[m++] = x;
        }
      }
      n = m;
      if (n == 0) return false;
      std::swap(poly, next);
    }
  glm::dvec3 lo = poly[0], hi = poly[0];
  for (int v = 1; v < n; ++v) {
    lo = glm::min(lo, poly[v]);
    hi = glm::max(hi, poly[v]);
  }
  *out_lower = glm::max(lo, lower);
  *out_upper = glm::min(hi, upper);
  return true;
}

}  // namespace rtcl
