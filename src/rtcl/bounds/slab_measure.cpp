#include "rtcl/bounds/slab_measure.hpp"

#include <cmath>
#include <vector>

#include <glm/glm.hpp>

namespace rtcl {

namespace {

struct Plane {
  glm::dvec3 n;  // outward
  double d;      // dot(n, x) <= d inside
};

// Sutherland–Hodgman against one half-space, keeping points within `tol` of
// the plane (so a zero-width slab keeps its face).
std::vector<glm::dvec3> clip(const std::vector<glm::dvec3>& poly, const Plane& p, double tol) {
  std::vector<glm::dvec3> out;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec3& a = poly[i];
    const glm::dvec3& b = poly[(i + 1) % poly.size()];
    double da = glm::dot(p.n, a) - p.d - tol, db = glm::dot(p.n, b) - p.d - tol;
    if (da <= 0.0) out.push_back(a);
    if ((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) out.push_back(a + (b - a) * (da / (da - db)));
  }
  return out;
}

glm::dvec3 polygon_area_vector(const std::vector<glm::dvec3>& poly) {
  glm::dvec3 s(0.0);
  for (std::size_t i = 1; i + 1 < poly.size(); ++i) s += glm::cross(poly[i] - poly[0], poly[i + 1] - poly[0]);
  return 0.5 * s;
}

}  // namespace

VolumeMeasure measure_slabs(const SlabVolume& v) {
  VolumeMeasure m;
  if (v.count <= 0) return m;
  std::vector<Plane> planes;
  for (int i = 0; i < v.count; ++i) {
    glm::dvec3 n(v.normal[i][0], v.normal[i][1], v.normal[i][2]);
    planes.push_back({n, v.d_far[i]});
    planes.push_back({-n, -static_cast<double>(v.d_near[i])});
  }
  // A square on each plane larger than the region: the region lies within
  // the contents' reach (|x| <= reach) widened by the slabs' own rounding.
  double scale = 0.0;
  for (const Plane& p : planes) scale = std::fmax(scale, std::fabs(p.d));
  double size = 4.0 * (scale + v.reach) + 1e-300;
  double tol = 1e-12 * size;
  std::vector<std::vector<glm::dvec3>> faces;
  for (std::size_t f = 0; f < planes.size(); ++f) {
    const Plane& p = planes[f];
    glm::dvec3 helper = std::fabs(p.n.x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    glm::dvec3 u = glm::normalize(glm::cross(p.n, helper)), w = glm::cross(p.n, u);
    glm::dvec3 c = p.n * (p.d / glm::dot(p.n, p.n));
    std::vector<glm::dvec3> poly = {c + size * (u + w), c + size * (-u + w), c + size * (-u - w), c + size * (u - w)};
    for (std::size_t g = 0; g < planes.size() && !poly.empty(); ++g)
      if (g != f) poly = clip(poly, planes[g], tol);
    if (poly.size() >= 3) faces.push_back(poly);
  }
  glm::dvec3 centre(0.0);
  std::size_t n = 0;
  for (const auto& poly : faces)
    for (const glm::dvec3& q : poly) centre += q, ++n;
  if (n == 0) return m;
  centre /= static_cast<double>(n);
  for (const auto& poly : faces) {
    glm::dvec3 a = polygon_area_vector(poly);
    double area = glm::length(a);
    m.area += area;
    // Cone from the centre: (1/3) * area * height, with the outward normal.
    if (area > 0.0) m.volume += glm::dot(a, poly[0] - centre) / 3.0;
  }
  m.volume = std::fmax(m.volume, 0.0);
  return m;
}

}  // namespace rtcl
