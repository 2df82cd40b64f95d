#include "rtcl/beam/screen_space.hpp"

#include <algorithm>
#include <cmath>

#include "rtcl/beam/polygon2d.hpp"

namespace rtcl::beam {

using glm::dvec2;
using glm::dvec3;

ScreenSpace screen_space(const CameraFrame& frame, std::uint32_t width, std::uint32_t height, const Geometry& geometry) {
  ScreenSpace s;
  s.frame = frame;
  s.width = width;
  s.height = height;
  s.forward = glm::normalize(frame.corner + 0.5 * width * frame.du + 0.5 * height * frame.dv);
  Aabb box = geometry.bounds();
  double reach = 0.0;
  for (int k = 0; k < 8; ++k) {
    dvec3 c((k & 1) ? box.upper.x : box.lower.x, (k & 2) ? box.upper.y : box.lower.y, (k & 4) ? box.upper.z : box.lower.z);
    reach = std::max(reach, glm::length(c - frame.origin));
  }
  s.near = near_fraction * reach;
  return s;
}

dvec2 project(const ScreenSpace& screen, const dvec3& p, double* depth) {
  const CameraFrame& f = screen.frame;
  dvec3 q = p - f.origin;
  // q / s = corner + x du + y dv, with forward . corner = 1 and du, dv
  // orthogonal to forward and to each other.
  double s = glm::dot(q, screen.forward);
  if (depth) *depth = s;
  dvec3 r = q / s - f.corner;
  return {glm::dot(r, f.du) / glm::dot(f.du, f.du), glm::dot(r, f.dv) / glm::dot(f.dv, f.dv)};
}

dvec3 unproject(const ScreenSpace& screen, const dvec3& inv_depth, const dvec2& xy) {
  const CameraFrame& f = screen.frame;
  double s = 1.0 / (inv_depth.x * xy.x + inv_depth.y * xy.y + inv_depth.z);
  return f.origin + s * (f.corner + xy.x * f.du + xy.y * f.dv);
}

namespace {

// Sutherland–Hodgman of a 3D polygon against dist(p) >= 0.
template <class Dist>
std::vector<dvec3> clip3(const std::vector<dvec3>& in, Dist dist) {
  std::vector<dvec3> out;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const dvec3 &a = in[i], &b = in[(i + 1) % in.size()];
    double da = dist(a), db = dist(b);
    if (da >= 0.0) out.push_back(a);
    if ((da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0)) out.push_back(a + (da / (da - db)) * (b - a));
  }
  return out;
}

}  // namespace

bool screen_polygon(const ScreenSpace& screen, const Geometry& geometry, std::uint32_t t, const glm::dmat4& to_world,
                    const glm::dvec4* keep_plane, double keep_margin, ScreenPolygon* out) {
  const CameraFrame& f = screen.frame;
  const double screen_area = double(screen.width) * screen.height;
  // One pixel of margin: fragments never reach the screen's border by rounding.
  const Convex rect = rectangle(-1.0, -1.0, screen.width + 1.0, screen.height + 1.0);
  dvec3 v[3];
  for (int k = 0; k < 3; ++k) v[k] = dvec3(to_world * glm::dvec4(dvec3(geometry.vertices[geometry.triangles[t][k]]), 1.0));
  dvec3 n = glm::cross(v[1] - v[0], v[2] - v[0]);
  double k = glm::dot(n, v[0] - f.origin);
  if (!(std::abs(k) > 0.0)) return false;  // zero area, or its plane holds the eye: seen edge-on
  // Near plane s >= near, in world space before the divide.
  std::vector<dvec3> clipped =
      clip3({v[0], v[1], v[2]}, [&](const dvec3& p) { return glm::dot(p - f.origin, screen.forward) - screen.near; });
  if (keep_plane)
    clipped = clip3(clipped, [&](const dvec3& p) { return glm::dot(*keep_plane, glm::dvec4(p, 1.0)) - keep_margin; });
  if (clipped.size() < 3) return false;
  std::vector<dvec2> projected;
  for (const dvec3& p : clipped) projected.push_back(project(screen, p));
  // Clipping leaves near-copies of a vertex (a spike, reflex by rounding)
  // where a plane passes through it: merged at 1e-9 of the screen's size.
  Convex c = make_strictly_convex(intersect(make_convex(projected), rect), 1e-9 * (screen.width + screen.height));
  if (c.v.size() < 3 || signed_area(c.v) < 1e-12 * screen_area) return false;
  out->v = std::move(c.v);
  out->inv_depth = dvec3(glm::dot(n, f.du), glm::dot(n, f.dv), glm::dot(n, f.corner)) / k;
  out->prim = t;
  return true;
}

std::vector<ScreenPolygon> screen_polygons(const ScreenSpace& screen, const Geometry& geometry,
                                           const glm::dmat4& to_world, const glm::dvec4* keep_plane,
                                           double keep_margin) {
  std::vector<ScreenPolygon> out;
  ScreenPolygon sp;
  for (std::size_t t = 0; t < geometry.triangles.size(); ++t)
    if (screen_polygon(screen, geometry, std::uint32_t(t), to_world, keep_plane, keep_margin, &sp))
      out.push_back(std::move(sp));
  return out;
}

}  // namespace rtcl::beam
