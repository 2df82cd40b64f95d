// 2D polygon booleans in double precision for beam clipping (Heckbert and
// Hanrahan 1984; lecture, 光束跟踪: "将它与 z 值排序表上第一个景物多边形在 xy
// 坐标平面上作二维布尔运算"). A Region is a list of convex polygons with
// pairwise disjoint interiors; concave shapes and holes are unions of convex
// pieces. Intersection with a convex polygon clips every piece by its edges
// (Sutherland–Hodgman); subtraction of a convex polygon splits each piece
// along the subtrahend's edges into at most n pieces outside it. Both never
// create overlaps, so a Region's area is the sum of its pieces' areas.
//
// Degenerate results: a piece whose area is below `min_area` (same unit as
// the coordinates squared) is dropped. Callers scale it with the beam:
// min_area = beam_min_area_fraction * area of the beam's cross-section, so
// the coverage lost per operation is at most that fraction of the beam per
// dropped piece, whatever the scene's scale.
#pragma once

#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

namespace rtcl::beam {

// Vertices counter-clockwise (positive signed area, y up or x right / y down
// consistently: only the sign convention matters). Fewer than 3 vertices:
// empty.
struct Convex {
  std::vector<glm::dvec2> v;
};
using Region = std::vector<Convex>;

// The fraction of a beam's cross-section below which a piece is dropped by
// beam clipping in double: far above the rounding of coordinates that are
// O(beam size) (1e-16 relative), far below any visible coverage.
inline constexpr double beam_min_area_fraction = 1e-12;

// Shoelace formula; counter-clockwise polygons are positive.
double signed_area(const std::vector<glm::dvec2>& polygon);
double area(const Region& region);

// The convex polygon through `vertices` in either orientation, made
// counter-clockwise; consecutive duplicates removed. No convexity check.
Convex make_convex(std::vector<glm::dvec2> vertices);
// A polygon meant to be convex made strictly convex: vertices within `merge`
// (max norm) of their predecessor, and vertices where the boundary does not
// turn left (collinear, or reflex by rounding, e.g. a spike of two
// near-copies of one vertex after clipping), are removed until none is left.
Convex make_strictly_convex(const Convex& polygon, double merge);
// Axis-aligned rectangle [x0, x1] x [y0, y1].
Convex rectangle(double x0, double y0, double x1, double y1);

// The half-plane a*x + b*y + c >= 0.
struct HalfPlane {
  double a = 0.0, b = 0.0, c = 0.0;
  double eval(const glm::dvec2& p) const { return a * p.x + b * p.y + c; }
};
// The inside (left) half-plane of the directed edge p -> q of a
// counter-clockwise polygon.
HalfPlane edge_half_plane(const glm::dvec2& p, const glm::dvec2& q);

// Sutherland–Hodgman against one half-plane; points with eval == 0 are kept.
Convex clip(const Convex& polygon, const HalfPlane& h);
// polygon ∩ convex.
Convex intersect(const Convex& polygon, const Convex& convex);
// polygon − convex: at most convex.v.size() pieces, each above min_area.
Region subtract(const Convex& polygon, const Convex& convex, double min_area);

Region intersect(const Region& region, const Convex& convex, double min_area);
Region subtract(const Region& region, const Convex& convex, double min_area);
Region intersect(const Region& a, const Region& b, double min_area);
Region subtract(const Region& a, const Region& b, double min_area);

// Point membership (boundary included) of a convex polygon / region.
bool contains(const Convex& polygon, const glm::dvec2& p);
bool contains(const Region& region, const glm::dvec2& p);

}  // namespace rtcl::beam
