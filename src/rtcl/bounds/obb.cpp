#include "rtcl/bounds/obb.hpp"

#include <cmath>
#include <limits>

#include "rtcl/bounds/point_input.hpp"
#include "rtcl/bounds/symmetric_eigen.hpp"

namespace rtcl {

namespace {

// Extents of the points along the rows of an orthonormal basis.
struct Fit {
  glm::dmat3 basis;  // columns are the axes
  glm::dvec3 lo, hi;
  double area = 0.0;
};

Fit evaluate(const std::vector<glm::vec3>& points, const glm::dmat3& basis) {
  Fit f{basis, glm::dvec3(std::numeric_limits<double>::infinity()),
        glm::dvec3(-std::numeric_limits<double>::infinity()), 0.0};
  for (const glm::vec3& p : points) {
    glm::dvec3 q(p);
    for (int k = 0; k < 3; ++k) {
      double d = glm::dot(basis[k], q);
      f.lo[k] = std::fmin(f.lo[k], d);
      f.hi[k] = std::fmax(f.hi[k], d);
    }
  }
  glm::dvec3 e = f.hi - f.lo;
  f.area = 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
  return f;
}

// Rotation of the basis about its own axis k by angle a (stays orthonormal).
glm::dmat3 rotated(const glm::dmat3& b, int k, double a) {
  int i = (k + 1) % 3, j = (k + 2) % 3;
  glm::dmat3 r = b;
  double c = std::cos(a), s = std::sin(a);
  r[i] = c * b[i] + s * b[j];
  r[j] = -s * b[i] + c * b[j];
  return r;
}

Fit refine(const std::vector<glm::vec3>& points, Fit best, double min_step) {
  for (double step = 0.25; step >= min_step; step *= 0.5) {
    for (int sweep = 0; sweep < 64; ++sweep) {
      bool improved = false;
      for (int k = 0; k < 3; ++k)
        for (double sign : {1.0, -1.0}) {
          Fit f = evaluate(points, rotated(best.basis, k, sign * step));
          if (f.area < best.area * (1.0 - 1e-12)) best = f, improved = true;
        }
      if (!improved) break;
    }
  }
  return best;
}

glm::dmat3 orthonormalised(glm::dmat3 b) {
  b[0] = glm::normalize(b[0]);
  b[1] = glm::normalize(b[1] - glm::dot(b[1], b[0]) * b[0]);
  b[2] = glm::cross(b[0], b[1]);
  return b;
}

// The points extreme (smallest or largest projection) along 258 directions
// spread over the sphere (a Fibonacci spiral): the hull vertices that matter
// most to a box's faces, a few hundred instead of every vertex. The fit
// refines on these; the final extents are taken over every point.
std::vector<glm::vec3> support_points(const std::vector<glm::vec3>& points) {
  constexpr int directions = 129;  // each gives its minimum and maximum
  if (points.size() <= 2 * directions) return points;
  std::vector<char> keep(points.size(), 0);
  for (int k = 0; k < directions; ++k) {
    double z = 1.0 - (2.0 * k + 1.0) / directions, r = std::sqrt(1.0 - z * z), phi = 2.399963229728653 * k;
    glm::dvec3 n(r * std::cos(phi), r * std::sin(phi), z);
    std::size_t lo = 0, hi = 0;
    double dlo = std::numeric_limits<double>::infinity(), dhi = -dlo;
    for (std::size_t i = 0; i < points.size(); ++i) {
      double d = glm::dot(n, glm::dvec3(points[i]));
      if (d < dlo) dlo = d, lo = i;
      if (d > dhi) dhi = d, hi = i;
    }
    keep[lo] = keep[hi] = 1;
  }
  std::vector<glm::vec3> out;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (keep[i]) out.push_back(points[i]);
  return out;
}

}  // namespace

glm::vec3 Obb::half_extent() const {
  return 0.5f * glm::vec3(d_far[0] - d_near[0], d_far[1] - d_near[1], d_far[2] - d_near[2]);
}

glm::vec3 Obb::center() const {
  glm::vec3 c(0.0f);
  for (int k = 0; k < 3; ++k) c += axis[k] * (0.5f * (d_near[k] + d_far[k]));
  return c;
}

double Obb::volume() const {
  double v = 1.0;
  for (int k = 0; k < 3; ++k) v *= static_cast<double>(d_far[k]) - d_near[k];
  return v;
}

double Obb::area() const {
  double e[3];
  for (int k = 0; k < 3; ++k) e[k] = static_cast<double>(d_far[k]) - d_near[k];
  return 2.0 * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0]);
}

SlabVolume Obb::record() const { return slab_record(3, axis, d_near, d_far, reach); }

Obb obb_of_points(const std::vector<glm::vec3>& points, const std::string& source, double min_step_rad) {
  check_points(points, source);
  glm::dvec3 mean(0.0);
  for (const glm::vec3& p : points) mean += glm::dvec3(p);
  mean /= static_cast<double>(points.size());
  glm::dmat3 cov(0.0);
  for (const glm::vec3& p : points) {
    glm::dvec3 d = glm::dvec3(p) - mean;
    cov += glm::outerProduct(d, d);
  }
  glm::dmat3 pca = orthonormalised(symmetric_eigen(cov).vectors);
  std::vector<glm::vec3> support = support_points(points);
  // Candidates measured on every point: the two refined starts and the
  // world axes themselves (so the result is never larger than the AABB).
  Fit best = evaluate(points, glm::dmat3(1.0));
  for (const glm::dmat3& start : {pca, glm::dmat3(1.0)}) {
    Fit f = evaluate(points, refine(support, evaluate(support, start), min_step_rad).basis);
    if (f.area < best.area) best = f;
  }

  Obb obb;
  for (int k = 0; k < 3; ++k) obb.axis[k] = glm::vec3(best.basis[k]);
  // Re-project on the float axes: they define the stored box.
  for (int k = 0; k < 3; ++k) {
    glm::dvec3 n(obb.axis[k]);
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const glm::vec3& p : points) {
      double d = glm::dot(n, glm::dvec3(p));
      lo = std::fmin(lo, d);
      hi = std::fmax(hi, d);
    }
    obb.d_near[k] = round_down(lo);
    obb.d_far[k] = round_up(hi);
  }
  obb.reach = reach_of(points);
  return obb;
}

}  // namespace rtcl
