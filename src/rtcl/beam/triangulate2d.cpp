#include "rtcl/beam/triangulate2d.hpp"

#include <algorithm>
#include <cmath>

#include "rtcl/error.hpp"

namespace rtcl::beam {

namespace {

using glm::dvec2;

double cross(const dvec2& o, const dvec2& a, const dvec2& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

// p in the closed triangle a, b, c (counter-clockwise).
bool in_triangle(const dvec2& p, const dvec2& a, const dvec2& b, const dvec2& c) {
  return cross(a, b, p) >= 0.0 && cross(b, c, p) >= 0.0 && cross(c, a, p) >= 0.0;
}

}  // namespace

Region triangulate(const std::vector<dvec2>& polygon, const std::string& what) {
  Convex ring = make_convex(polygon);  // orientation and duplicates only
  std::vector<dvec2> v = std::move(ring.v);
  if (v.size() < 3) throw Error(what + ": fewer than 3 distinct vertices");
  if (!(signed_area(v) > 0.0)) throw Error(what + ": zero area");
  Region out;
  while (v.size() > 3) {
    const std::size_t n = v.size();
    bool cut = false;
    for (std::size_t i = 0; i < n && !cut; ++i) {
      const dvec2& a = v[(i + n - 1) % n];
      const dvec2& b = v[i];
      const dvec2& c = v[(i + 1) % n];
      double turn = cross(a, b, c);
      if (turn == 0.0) {  // collinear (or a spike back along the edge): no area
        v.erase(v.begin() + static_cast<std::ptrdiff_t>(i));
        cut = true;
        break;
      }
      if (turn < 0.0) continue;  // reflex
      bool blocked = false;
      for (std::size_t j = 0; j < n && !blocked; ++j) {
        if (j == i || j == (i + 1) % n || j == (i + n - 1) % n) continue;
        if (v[j] == a || v[j] == b || v[j] == c) continue;
        blocked = in_triangle(v[j], a, b, c);
      }
      if (blocked) continue;
      out.push_back(Convex{{a, b, c}});
      v.erase(v.begin() + static_cast<std::ptrdiff_t>(i));
      cut = true;
    }
    if (!cut) throw Error(what + ": not a simple polygon (no ear can be cut)");
  }
  if (cross(v[0], v[1], v[2]) > 0.0) out.push_back(Convex{{v[0], v[1], v[2]}});
  return out;
}

}  // namespace rtcl::beam
