// 2D polygon booleans (src/rtcl/beam/polygon2d.*, triangulate2d.*) against an
// independent reference: even-odd point membership in the original simple
// polygons on a dense jittered grid (exact away from the boundaries), and the
// area of that grid's cells against the shoelace area of the result within a
// band set by how many cells the boundaries can cross.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "rtcl/beam/polygon2d.hpp"
#include "rtcl/beam/triangulate2d.hpp"
#include "rtcl/error.hpp"

namespace rtcl::test {
namespace {

using beam::Convex;
using beam::Region;
using glm::dvec2;
using Ring = std::vector<dvec2>;

// Even-odd crossing test: the reference membership, independent of the
// convex-piece representation.
bool inside_ring(const Ring& r, const dvec2& p) {
  bool in = false;
  for (std::size_t i = 0, j = r.size() - 1; i < r.size(); j = i++) {
    const dvec2 &a = r[i], &b = r[j];
    if ((a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y)) in = !in;
  }
  return in;
}

double segment_distance(const dvec2& p, const dvec2& a, const dvec2& b) {
  dvec2 ab = b - a;
  double len2 = glm::dot(ab, ab);
  double t = len2 > 0.0 ? glm::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return glm::length(p - (a + t * ab));
}

double boundary_distance(const Ring& r, const dvec2& p) {
  double d = INFINITY;
  for (std::size_t i = 0; i < r.size(); ++i) d = std::min(d, segment_distance(p, r[i], r[(i + 1) % r.size()]));
  return d;
}

double perimeter(const Ring& r) {
  double s = 0.0;
  for (std::size_t i = 0; i < r.size(); ++i) s += glm::length(r[(i + 1) % r.size()] - r[i]);
  return s;
}

// A star-shaped ring around c: convex when `convex` (one radius, sorted
// angles), else random radii in [0.3, 1] r (concave in general).
Ring random_ring(std::mt19937& rng, dvec2 c, double r, int n, bool convex) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> angles;
  for (int i = 0; i < n; ++i) angles.push_back(2.0 * std::numbers::pi * u(rng));
  std::sort(angles.begin(), angles.end());
  Ring ring;
  for (double a : angles) {
    double radius = convex ? r : r * (0.3 + 0.7 * u(rng));
    ring.push_back(c + radius * dvec2(std::cos(a), std::sin(a)));
  }
  return ring;
}

enum class Op { intersect, subtract };

// Checks result = a op b on a jittered n x n grid over [lo, hi]^2: exact
// membership at every sample farther than `guard` from both boundaries, and
// the result's shoelace area against the samples' estimate. A boundary
// segment of length L meets at most sqrt(2) L / h + 2 cells of side h, and
// only those cells can be misjudged: the band is that many cells' area.
void check_op(const Ring& a, const Ring& b, const Region& result, Op op, double lo, double hi, int n = 256) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double h = (hi - lo) / n;
  const double guard = 1e-9 * (hi - lo);
  long inside = 0, checked = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      dvec2 p(lo + (i + u(rng)) * h, lo + (j + u(rng)) * h);
      bool in_a = inside_ring(a, p), in_b = inside_ring(b, p);
      bool want = op == Op::intersect ? (in_a && in_b) : (in_a && !in_b);
      inside += want;
      if (boundary_distance(a, p) < guard || boundary_distance(b, p) < guard) continue;
      ++checked;
      int pieces = 0;
      for (const Convex& c : result) pieces += beam::contains(c, p);
      ASSERT_EQ(pieces > 0, want) << "at (" << p.x << ", " << p.y << ")";
      ASSERT_LE(pieces, 1) << "pieces overlap at (" << p.x << ", " << p.y << ")";
    }
  EXPECT_GT(checked, n * n * 9 / 10);
  double cells = std::sqrt(2.0) * (perimeter(a) + perimeter(b)) / h + 2.0 * double(a.size() + b.size());
  EXPECT_NEAR(beam::area(result), inside * h * h, cells * h * h);
  for (const Convex& c : result) EXPECT_GT(beam::signed_area(c.v), 0.0);
}

Region as_region(const Ring& r) { return beam::triangulate(r); }

TEST(Polygon2d, RandomConvexAndConcaveAgainstPointMembership) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (int trial = 0; trial < 12; ++trial) {
    bool convex = trial % 2 == 0;
    // Scale 1e-3 and 1e3 on alternate trials: no absolute tolerance.
    double s = trial % 3 == 0 ? 1e-3 : trial % 3 == 1 ? 1.0 : 1e3;
    Ring a = random_ring(rng, s * dvec2(u(rng), u(rng)), s, 5 + trial % 7, convex);
    Ring b = random_ring(rng, s * dvec2(u(rng), u(rng)), s, 4 + trial % 5, convex || trial % 4 == 1);
    Region ra = as_region(a), rb = as_region(b);
    double min_area = beam::beam_min_area_fraction * s * s;
    SCOPED_TRACE(trial);
    check_op(a, b, beam::intersect(ra, rb, min_area), Op::intersect, -2.0 * s, 2.0 * s);
    check_op(a, b, beam::subtract(ra, rb, min_area), Op::subtract, -2.0 * s, 2.0 * s);
  }
}

TEST(Polygon2d, SquareWithAHoleThenIntersected) {
  Ring outer{{0, 0}, {4, 0}, {4, 4}, {0, 4}}, inner{{1, 1}, {3, 1}, {3, 3}, {1, 3}};
  Region holed = beam::subtract(as_region(outer), as_region(inner), 1e-12);
  EXPECT_DOUBLE_EQ(beam::area(holed), 12.0);
  EXPECT_FALSE(beam::contains(holed, dvec2(2.0, 2.0)));
  EXPECT_TRUE(beam::contains(holed, dvec2(0.5, 2.0)));
  // A band across the hole: [0, 4] x [1.5, 2.5] minus the hole's [1, 3] x [1.5, 2.5].
  Region band = beam::intersect(holed, beam::rectangle(-1, 1.5, 5, 2.5), 1e-12);
  EXPECT_NEAR(beam::area(band), 4.0 - 2.0, 1e-12);
  EXPECT_TRUE(beam::contains(band, dvec2(0.5, 2.0)));
  EXPECT_FALSE(beam::contains(band, dvec2(2.0, 2.0)));
  // Filling the hole back gives the square.
  Region refilled = holed;
  refilled.push_back(beam::make_convex(inner));
  EXPECT_NEAR(beam::area(refilled), 16.0, 1e-12);
}

TEST(Polygon2d, SharedEdgesAndVertices) {
  Convex left = beam::rectangle(0, 0, 1, 1), right = beam::rectangle(1, 0, 2, 1);
  // Touching along an edge: no common area, nothing removed.
  EXPECT_TRUE(beam::intersect(Region{left}, right, 1e-12).empty());
  Region rest = beam::subtract(left, right, 1e-12);
  EXPECT_DOUBLE_EQ(beam::area(rest), 1.0);
  // Touching at one vertex only.
  Convex corner = beam::rectangle(1, 1, 2, 2);
  EXPECT_TRUE(beam::intersect(Region{left}, corner, 1e-12).empty());
  EXPECT_DOUBLE_EQ(beam::area(beam::subtract(left, corner, 1e-12)), 1.0);
  // The same polygon: intersection is itself, difference empty.
  EXPECT_DOUBLE_EQ(beam::area(beam::intersect(Region{left}, left, 1e-12)), 1.0);
  EXPECT_TRUE(beam::subtract(left, left, 1e-12).empty());
  // Half of a square split along its diagonal: the two triangles tile it.
  Convex lower = beam::make_convex({{0, 0}, {1, 0}, {1, 1}}), upper = beam::make_convex({{0, 0}, {1, 1}, {0, 1}});
  EXPECT_NEAR(beam::area(beam::subtract(left, lower, 1e-12)), 0.5, 1e-15);
  EXPECT_TRUE(beam::subtract(beam::subtract(left, lower, 1e-12), upper, 1e-12).empty());
}

TEST(Polygon2d, CollinearAndDegenerateInput) {
  // Collinear vertices along the edges change nothing.
  Convex square = beam::make_convex({{0, 0}, {0.5, 0}, {1, 0}, {1, 0.5}, {1, 1}, {0, 1}, {0, 1}});
  EXPECT_DOUBLE_EQ(beam::signed_area(square.v), 1.0);
  EXPECT_NEAR(beam::area(beam::subtract(square, beam::rectangle(0.25, -1, 0.75, 2), 1e-12)), 0.5, 1e-15);
  // Clockwise input is reoriented.
  EXPECT_DOUBLE_EQ(beam::signed_area(beam::make_convex({{0, 0}, {0, 1}, {1, 1}, {1, 0}}).v), 1.0);
  // A zero-area polygon (a segment through the square) removes nothing and meets nothing.
  Convex segment = beam::make_convex({{-1, 0.5}, {0.5, 0.5}, {2, 0.5}});
  EXPECT_DOUBLE_EQ(beam::area(beam::subtract(square, segment, 1e-12)), 1.0);
  EXPECT_TRUE(beam::intersect(Region{square}, segment, 1e-12).empty());
  // A sliver below min_area is dropped; min_area scales with the beam.
  for (double s : {1e-6, 1.0, 1e6}) {
    Convex big = beam::rectangle(0, 0, s, s);
    Region sliver = beam::subtract(big, beam::rectangle(0, 0, s * (1 - 1e-14), s), beam::beam_min_area_fraction * s * s);
    EXPECT_TRUE(sliver.empty()) << s;
    Region strip = beam::subtract(big, beam::rectangle(0, 0, s * 0.999, s), beam::beam_min_area_fraction * s * s);
    EXPECT_NEAR(beam::area(strip), 1e-3 * s * s, 1e-12 * s * s) << s;
  }
  // A spike of two near-copies of one vertex in the wrong order, and an
  // exactly collinear vertex, are removed; the square is what remains.
  beam::Convex spiky{{{0, 0}, {0.5, 0}, {1, 0}, {1, 1}, {0, 1}, {1e-13, 1}, {0, 1}, {0, 0.5}}};
  beam::Convex clean = beam::make_strictly_convex(spiky, 1e-12);
  EXPECT_EQ(clean.v.size(), 4u);
  EXPECT_NEAR(beam::signed_area(clean.v), 1.0, 1e-12);
  EXPECT_TRUE(beam::make_strictly_convex(beam::Convex{{{0, 0}, {1, 1}, {2, 2}}}, 1e-12).v.empty());
  // Ear clipping of an L shape and its errors.
  Region l = beam::triangulate({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}});
  EXPECT_DOUBLE_EQ(beam::area(l), 3.0);
  EXPECT_THROW(beam::triangulate({{0, 0}, {1, 1}, {2, 2}}, "beam"), Error);
  EXPECT_THROW(beam::triangulate({{0, 0}, {1, 0}}, "beam"), Error);
}

}  // namespace
}  // namespace rtcl::test
