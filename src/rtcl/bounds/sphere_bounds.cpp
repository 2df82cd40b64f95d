#include "rtcl/bounds/sphere_bounds.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "rtcl/bounds/point_input.hpp"

namespace rtcl {

namespace {

struct Ball {
  glm::dvec3 c{0.0};
  double r = 0.0;
};

// Containment with a relative tolerance of 1e-12 of the radius (and of the
// points' scale, for radius 0), so that points on the boundary computed in
// double do not count as outside.
bool contains(const Ball& b, const glm::dvec3& p, double scale) {
  double d = glm::length(p - b.c);
  return d <= b.r + 1e-12 * (b.r + scale);
}

void grow(Ball& s, const glm::dvec3& p) {
  glm::dvec3 v = p - s.c;
  double d = glm::length(v);
  if (d <= s.r) return;
  double r = 0.5 * (s.r + d);
  s.c += v * ((r - s.r) / d);
  s.r = r;
}

Ball ritter_start(const std::vector<glm::dvec3>& p) {
  std::size_t lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      if (p[i][k] < p[lo[k]][k]) lo[k] = i;
      if (p[i][k] > p[hi[k]][k]) hi[k] = i;
    }
  int best = 0;
  double best_d = -1.0;
  for (int k = 0; k < 3; ++k) {
    double d = glm::length(p[hi[k]] - p[lo[k]]);
    if (d > best_d) best_d = d, best = k;
  }
  return {0.5 * (p[lo[best]] + p[hi[best]]), 0.5 * best_d};
}

Ball ball2(const glm::dvec3& a, const glm::dvec3& b) { return {0.5 * (a + b), 0.5 * glm::length(b - a)}; }

Ball smallest_containing(const std::vector<Ball>& candidates, const std::vector<glm::dvec3>& pts, double scale) {
  Ball best{glm::dvec3(0.0), std::numeric_limits<double>::infinity()};
  for (const Ball& b : candidates) {
    if (!(b.r < best.r)) continue;
    bool all = true;
    for (const glm::dvec3& p : pts) all = all && contains(b, p, scale);
    if (all) best = b;
  }
  return best;
}

// The smallest sphere with a, b, c on its boundary (their circumcircle);
// collinear (relative |cross|^2 below 1e-20): the smallest of the pair
// spheres that contains all three.
Ball ball3(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, double scale) {
  glm::dvec3 u = b - a, v = c - a, w = glm::cross(u, v);
  double w2 = glm::dot(w, w), u2 = glm::dot(u, u), v2 = glm::dot(v, v);
  if (w2 <= 1e-20 * u2 * v2 || w2 == 0.0) return smallest_containing({ball2(a, b), ball2(a, c), ball2(b, c)}, {a, b, c}, scale);
  glm::dvec3 off = (u2 * glm::cross(v, w) + v2 * glm::cross(w, u)) / (2.0 * w2);
  return {a + off, glm::length(off)};
}

// The sphere through a, b, c, d; coplanar (relative determinant below
// 1e-10): the smallest of the triple and pair spheres containing all four.
Ball ball4(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d, double scale) {
  glm::dvec3 u = b - a, v = c - a, w = d - a;
  double det = glm::dot(u, glm::cross(v, w));
  double norm = glm::length(u) * glm::length(v) * glm::length(w);
  if (std::fabs(det) <= 1e-10 * norm || det == 0.0)
    return smallest_containing({ball3(a, b, c, scale), ball3(a, b, d, scale), ball3(a, c, d, scale),
                                ball3(b, c, d, scale), ball2(a, b), ball2(a, c), ball2(a, d), ball2(b, c),
                                ball2(b, d), ball2(c, d)},
                               {a, b, c, d}, scale);
  // Solve 2 [u v w]^T x = (|u|^2, |v|^2, |w|^2) by Cramer's rule.
  glm::dvec3 off = (glm::dot(u, u) * glm::cross(v, w) + glm::dot(v, v) * glm::cross(w, u) +
                    glm::dot(w, w) * glm::cross(u, v)) /
                   (2.0 * det);
  return {a + off, glm::length(off)};
}

std::vector<glm::dvec3> to_double(const std::vector<glm::vec3>& points) {
  std::vector<glm::dvec3> p;
  p.reserve(points.size());
  for (const glm::vec3& q : points) p.emplace_back(q);
  return p;
}

double scale_of(const std::vector<glm::dvec3>& p) {
  double s = 0.0;
  for (const glm::dvec3& q : p) s = std::fmax(s, glm::length(q));
  return s;
}

BoundingSphere to_float(const Ball& b, const std::vector<glm::vec3>& points) {
  BoundingSphere s;
  s.center = glm::vec3(b.c);
  double r = b.r;
  for (const glm::vec3& p : points) r = std::fmax(r, glm::length(glm::dvec3(p) - glm::dvec3(s.center)));
  s.radius = round_up(r);
  s.reach = reach_of(points);
  return s;
}

}  // namespace

double BoundingSphere::volume() const {
  double r = radius;
  return 4.0 / 3.0 * std::numbers::pi * r * r * r;
}

double BoundingSphere::area() const {
  double r = radius;
  return 4.0 * std::numbers::pi * r * r;
}

SphereVolume BoundingSphere::record() const {
  SphereVolume v{};
  v.cx = center.x;
  v.cy = center.y;
  v.cz = center.z;
  v.r = radius;
  v.reach = reach;
  return v;
}

BoundingSphere ritter_sphere(const std::vector<glm::vec3>& points, const std::string& source) {
  check_points(points, source);
  std::vector<glm::dvec3> p = to_double(points);
  Ball s = ritter_start(p);
  for (const glm::dvec3& q : p) grow(s, q);
  return to_float(s, points);
}

BoundingSphere iterated_ritter_sphere(const std::vector<glm::vec3>& points, const std::string& source, int rounds) {
  check_points(points, source);
  std::vector<glm::dvec3> p = to_double(points);
  Ball best = ritter_start(p);
  for (const glm::dvec3& q : p) grow(best, q);
  std::mt19937 rng(12345u);
  for (int round = 0; round < rounds; ++round) {
    std::shuffle(p.begin(), p.end(), rng);
    Ball s{best.c, 0.95 * best.r};
    for (const glm::dvec3& q : p) grow(s, q);
    if (s.r < best.r) best = s;
  }
  return to_float(best, points);
}

BoundingSphere exact_sphere(const std::vector<glm::vec3>& points, const std::string& source) {
  check_points(points, source);
  std::vector<glm::dvec3> p = to_double(points);
  double scale = scale_of(p);
  std::mt19937 rng(2024u);
  std::shuffle(p.begin(), p.end(), rng);
  // Welzl, iteratively: the ball of p[0..i] is rebuilt with p[i] on its
  // boundary whenever p[i] falls outside the ball of p[0..i-1], and so on
  // for up to three more fixed points.
  Ball b{p[0], 0.0};
  for (std::size_t i = 1; i < p.size(); ++i) {
    if (contains(b, p[i], scale)) continue;
    b = {p[i], 0.0};
    for (std::size_t j = 0; j < i; ++j) {
      if (contains(b, p[j], scale)) continue;
      b = ball2(p[i], p[j]);
      for (std::size_t k = 0; k < j; ++k) {
        if (contains(b, p[k], scale)) continue;
        b = ball3(p[i], p[j], p[k], scale);
        for (std::size_t l = 0; l < k; ++l) {
          if (contains(b, p[l], scale)) continue;
          b = ball4(p[i], p[j], p[k], p[l], scale);
        }
      }
    }
  }
  return to_float(b, points);
}

}  // namespace rtcl
