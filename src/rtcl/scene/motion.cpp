#include "rtcl/scene/motion.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "rtcl/error.hpp"

namespace rtcl {

namespace {

std::string number(double x) {
  std::ostringstream out;
  out << x;
  return out.str();
}

}  // namespace

bool blend_keeps_determinant_sign(const glm::dmat3& open, const glm::dmat3& close, double t0, double t1) {
  auto blended_determinant = [&](double t) { return glm::determinant((1.0 - t) * open + t * close); };
  double d0 = blended_determinant(t0);
  if (!(d0 != 0.0) || !std::isfinite(d0)) return false;
  if (!(t1 > t0)) return true;
  // The cubic's sign at both ends and at the critical points inside (the
  // roots of its derivative), its coefficients from four exact samples
  // (Lagrange interpolation at t0 .. t1).
  // p(s) = det(blend(t0 + s (t1 - t0))), s in [0, 1]: samples at s = 0, 1/3, 2/3, 1.
  double y[4];
  for (int k = 0; k < 4; ++k) y[k] = blended_determinant(t0 + (t1 - t0) * k / 3.0);
  // Newton forward differences on the unit step h = 1/3 -> power basis in s.
  double a0 = y[0];
  double d1 = y[1] - y[0], d2 = y[2] - 2 * y[1] + y[0], d3 = y[3] - 3 * y[2] + 3 * y[1] - y[0];
  // p(s) = a0 + d1 * x + d2 * x (x - 1) / 2 + d3 * x (x - 1) (x - 2) / 6 with x = 3 s.
  double c3 = 27.0 * d3 / 6.0;
  double c2 = 9.0 * (d2 / 2.0 - d3 / 2.0);
  double c1 = 3.0 * (d1 - d2 / 2.0 + d3 / 3.0);
  auto p = [&](double s) { return a0 + s * (c1 + s * (c2 + s * c3)); };
  std::vector<double> points{0.0, 1.0};
  // p'(s) = c1 + 2 c2 s + 3 c3 s^2.
  double qa = 3.0 * c3, qb = 2.0 * c2, qc = c1;
  double disc = qb * qb - 4.0 * qa * qc;
  if (disc >= 0.0) {
    // The stable form (no cancellation when qa is near zero).
    double q = -0.5 * (qb + std::copysign(std::sqrt(disc), qb));
    if (q != 0.0) points.push_back(qc / q);
    if (qa != 0.0) points.push_back(q / qa);
  }
  for (double s : points) {
    if (!(s >= 0.0 && s <= 1.0)) continue;
    double v = s == 0.0 ? y[0] : s == 1.0 ? y[3] : p(s);
    // Relative to the scale of the determinant: a value within rounding of
    // zero counts as singular.
    if (!(v * d0 > 0.0) || std::abs(v) <= 1e-12 * std::max(std::abs(d0), std::abs(y[3]))) return false;
  }
  return true;
}

bool scene_moves(const SceneDescription& scene) {
  return std::any_of(scene.meshes.begin(), scene.meshes.end(), [](const SceneMesh& m) { return m.end_transform.has_value(); }) ||
         std::any_of(scene.spheres.begin(), scene.spheres.end(), [](const SceneSphere& s) { return s.moving; });
}

glm::dmat4 transform_at(const SceneMesh& mesh, double time) {
  if (!mesh.end_transform) return mesh.transform;
  return (1.0 - time) * mesh.transform + time * *mesh.end_transform;
}

SceneSphere sphere_at(const SceneSphere& sphere, double time) {
  SceneSphere s = sphere;
  if (!sphere.moving) return s;
  s.center = (1.0 - time) * sphere.center + time * sphere.end_center;
  s.radius = (1.0 - time) * sphere.radius + time * sphere.end_radius;
  s.moving = false;
  return s;
}

SceneDescription scene_at(const SceneDescription& scene, double time) {
  SceneDescription out = scene;
  for (SceneMesh& m : out.meshes) {
    m.transform = transform_at(m, time);
    m.end_transform.reset();
  }
  for (SceneSphere& s : out.spheres) s = sphere_at(s, time);
  return out;
}

void check_motion(const SceneDescription& scene, double t0, double t1) {
  if (!std::isfinite(t0) || !std::isfinite(t1) || t0 > t1)
    throw Error(scene.source + ": camera.shutter: the interval [" + number(t0) + ", " + number(t1) +
                "] must be finite with open <= close");
  for (const SceneMesh& m : scene.meshes)
    if (m.end_transform && !blend_keeps_determinant_sign(glm::dmat3(m.transform), glm::dmat3(*m.end_transform), t0, t1))
      throw Error((m.motion_key.empty() ? scene.source + ": mesh " + m.name : m.motion_key) +
                  ": the blend of the two keyframe transforms is singular at some time in [" + number(t0) + ", " +
                  number(t1) + "] (the object would collapse onto a plane; a rotation of 180 degrees or more cannot "
                  "be blended, split it into smaller steps)");
  for (std::size_t i = 0; i < scene.spheres.size(); ++i) {
    const SceneSphere& s = scene.spheres[i];
    if (!s.moving) continue;
    double r0 = sphere_at(s, t0).radius, r1 = sphere_at(s, t1).radius;
    if (!(r0 > 0.0 && r1 > 0.0))
      throw Error((s.motion_key.empty() ? scene.source + ": sphere " + std::to_string(i) : s.motion_key) +
                  ": the radius reaches zero at some time in [" + number(t0) + ", " + number(t1) + "]");
  }
}

}  // namespace rtcl
