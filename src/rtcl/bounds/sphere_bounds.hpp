// Bounding spheres of a point set (lecture, 包围球).
//
// - ritter_sphere: the lecture's O(n) approximation (Ritter 1990), exactly
//   as given: of the three pairs of points with the smallest and largest x,
//   y and z, the farthest-apart pair is the start's diameter; then one pass
//   over the points, each point P outside the current sphere S replacing S
//   by the sphere through P internally tangent to S (centre moved towards P
//   by half of P's distance outside, radius grown by the same half).
// - iterated_ritter_sphere: the lecture's "iterate several times": from the
//   best sphere so far, shrink the radius by 5% and repeat the growing pass
//   over the points in a new (fixed-seed pseudo-random) order, keeping the
//   smaller sphere; `rounds` passes (default 16). A growing pass always ends
//   with every point inside, whatever the start (each step's sphere contains
//   the previous one), so every round's result bounds the points.
// - exact_sphere: the minimum enclosing sphere by Welzl's randomized
//   algorithm (Welzl 1991) in its iterative form: a shuffle, then four
//   nested loops (0..3 points fixed on the boundary), expected O(n), no
//   recursion. Boundary spheres of degenerate supports (collinear triples,
//   coplanar quadruples, which exact arithmetic never asks for but rounding
//   can) fall back to the smallest sphere of a subset that contains them all.
//
// All computations are in double; the result is rounded to float outward:
// the centre to the nearest float, the radius up to cover every point's
// distance from that float centre, so the float sphere contains every point.
// Degenerate input: see point_input.hpp (one or equal points: radius 0).
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/bounds/bounds_layouts.hpp"

namespace rtcl {

struct BoundingSphere {
  glm::vec3 center{0.0f};
  float radius = 0.0f;  // world units
  float reach = 0.0f;   // max |p| over the contents (SphereVolume::reach)

  double volume() const;
  double area() const;
  SphereVolume record() const;
};

BoundingSphere ritter_sphere(const std::vector<glm::vec3>& points, const std::string& source);
BoundingSphere iterated_ritter_sphere(const std::vector<glm::vec3>& points, const std::string& source,
                                      int rounds = 16);
BoundingSphere exact_sphere(const std::vector<glm::vec3>& points, const std::string& source);

}  // namespace rtcl
