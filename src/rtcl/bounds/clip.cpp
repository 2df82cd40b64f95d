#include "rtcl/bounds/clip.hpp"

#include <algorithm>

namespace rtcl {

namespace {

// A convex polygon clipped by one plane gains at most one vertex: 3 + 6,
// and one more for the split plane of clip_triangle_split.
constexpr int kMaxVertices = 10;

struct Polygon {
  glm::dvec3 v[kMaxVertices];
  int n = 0;
};

// Keeps the part of `poly` with sign * (p[axis] - bound) >= 0, into `out`
// (which may be `poly` itself when the plane keeps it whole).
void clip_plane(const Polygon& poly, int axis, double bound, double sign, Polygon* out) {
  bool inside = true;
  for (int i = 0; i < poly.n && inside; ++i) inside = sign * (poly.v[i][axis] - bound) >= 0.0;
  if (inside) {  // the plane keeps the polygon as it is
    if (out != &poly) *out = poly;
    return;
  }
  Polygon next;
  for (int i = 0; i < poly.n; ++i) {
    const glm::dvec3 &p = poly.v[i], &q = poly.v[i + 1 == poly.n ? 0 : i + 1];
    double dp = sign * (p[axis] - bound), dq = sign * (q[axis] - bound);
    if (dp >= 0.0) next.v[next.n++] = p;
    if ((dp >= 0.0) != (dq >= 0.0) && next.n < kMaxVertices) {
      glm::dvec3 x = p + (q - p) * (dp / (dp - dq));
      x[axis] = bound;  // on the plane, whatever the rounding of the interpolation
      next.v[next.n++] = x;
    }
  }
  *out = next;
}

// The polygon's bounds within [lower, upper]; false when it is empty.
bool bounds_within(const Polygon& poly, const glm::dvec3& lower, const glm::dvec3& upper, glm::dvec3* out_lower,
                   glm::dvec3* out_upper) {
  if (poly.n == 0) return false;
  glm::dvec3 lo = poly.v[0], hi = poly.v[0];
  for (int i = 1; i < poly.n; ++i) {
    lo = glm::min(lo, poly.v[i]);
    hi = glm::max(hi, poly.v[i]);
  }
  *out_lower = glm::max(lo, lower);
  *out_upper = glm::min(hi, upper);
  return true;
}

// The triangle clipped to the six planes of [lower, upper].
Polygon clip_to_box(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& lower,
                    const glm::dvec3& upper) {
  Polygon poly;
  poly.v[0] = a, poly.v[1] = b, poly.v[2] = c;
  poly.n = 3;
  for (int axis = 0; axis < 3 && poly.n > 0; ++axis) {
    clip_plane(poly, axis, lower[axis], 1.0, &poly);
    if (poly.n > 0) clip_plane(poly, axis, upper[axis], -1.0, &poly);
  }
  return poly;
}

}  // namespace

bool clip_triangle_bounds(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& lower,
                          const glm::dvec3& upper, glm::dvec3* out_lower, glm::dvec3* out_upper) {
  return bounds_within(clip_to_box(a, b, c, lower, upper), lower, upper, out_lower, out_upper);
}

ClipSplit clip_triangle_split(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& lower,
                              const glm::dvec3& upper, int axis, double below_upper, double above_lower) {
  Polygon poly = clip_to_box(a, b, c, lower, upper);
  ClipSplit out;
  Polygon side;
  glm::dvec3 box_upper = upper, box_lower = lower;
  box_upper[axis] = below_upper;
  box_lower[axis] = above_lower;
  clip_plane(poly, axis, below_upper, -1.0, &side);
  out.below = bounds_within(side, lower, box_upper, &out.below_lower, &out.below_upper);
  clip_plane(poly, axis, above_lower, 1.0, &side);
  out.above = bounds_within(side, box_lower, upper, &out.above_lower, &out.above_upper);
  return out;
}

}  // namespace rtcl
