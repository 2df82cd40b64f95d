#include "rtcl/beam/polygon2d.hpp"

#include <algorithm>
#include <cmath>

namespace rtcl::beam {

namespace {

using glm::dvec2;

void drop_duplicates(std::vector<dvec2>& v) {
  std::vector<dvec2> out;
  out.reserve(v.size());
  for (const dvec2& p : v)
    if (out.empty() || p != out.back()) out.push_back(p);
  while (out.size() > 1 && out.front() == out.back()) out.pop_back();
  v = std::move(out);
}

struct Box2 {
  dvec2 lo{INFINITY}, hi{-INFINITY};
};
Box2 box_of(const Convex& c) {
  Box2 b;
  for (const dvec2& p : c.v) {
    b.lo = glm::min(b.lo, p);
    b.hi = glm::max(b.hi, p);
  }
  return b;
}
bool disjoint(const Box2& a, const Box2& b) {
  return a.hi.x < b.lo.x || b.hi.x < a.lo.x || a.hi.y < b.lo.y || b.hi.y < a.lo.y;
}

bool empty(const Convex& c) { return c.v.size() < 3; }

}  // namespace

double signed_area(const std::vector<dvec2>& polygon) {
  double sum = 0.0;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) {
    const dvec2& p = polygon[i];
    const dvec2& q = polygon[(i + 1) % n];
    sum += p.x * q.y - q.x * p.y;
  }
  return 0.5 * sum;
}

double area(const Region& region) {
  double sum = 0.0;
  for (const Convex& c : region) sum += signed_area(c.v);
  return sum;
}

Convex make_convex(std::vector<dvec2> vertices) {
  drop_duplicates(vertices);
  if (signed_area(vertices) < 0.0) std::reverse(vertices.begin(), vertices.end());
  return Convex{std::move(vertices)};
}

Convex make_strictly_convex(const Convex& polygon, double merge) {
  std::vector<dvec2> v = polygon.v;
  bool changed = true;
  while (changed && v.size() >= 3) {
    changed = false;
    for (std::size_t i = 0; i < v.size() && v.size() >= 3; ++i) {
      const dvec2& a = v[(i + v.size() - 1) % v.size()];
      const dvec2& b = v[i];
      const dvec2& c = v[(i + 1) % v.size()];
      dvec2 d = glm::abs(b - a);
      double turn = (b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x);
      if (std::max(d.x, d.y) <= merge || !(turn > 0.0)) {
        v.erase(v.begin() + static_cast<std::ptrdiff_t>(i));
        changed = true;
        break;
      }
    }
  }
  if (v.size() < 3) v.clear();
  return Convex{std::move(v)};
}

Convex rectangle(double x0, double y0, double x1, double y1) {
  return Convex{{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}};
}

HalfPlane edge_half_plane(const dvec2& p, const dvec2& q) {
  // cross(q - p, x - p) >= 0: left of p -> q.
  HalfPlane h;
  h.a = -(q.y - p.y);
  h.b = q.x - p.x;
  h.c = -(h.a * p.x + h.b * p.y);
  return h;
}

Convex clip(const Convex& polygon, const HalfPlane& h) {
  Convex out;
  const std::size_t n = polygon.v.size();
  if (n < 3) return out;
  out.v.reserve(n + 1);
  for (std::size_t i = 0; i < n; ++i) {
    const dvec2& p = polygon.v[i];
    const dvec2& q = polygon.v[(i + 1) % n];
    double dp = h.eval(p), dq = h.eval(q);
    if (dp >= 0.0) out.v.push_back(p);
    if ((dp > 0.0 && dq < 0.0) || (dp < 0.0 && dq > 0.0)) {
      double t = dp / (dp - dq);  // in (0, 1): the sign change
      out.v.push_back(p + t * (q - p));
    }
  }
  drop_duplicates(out.v);
  if (out.v.size() < 3) out.v.clear();
  return out;
}

Convex intersect(const Convex& polygon, const Convex& convex) {
  if (empty(polygon) || empty(convex) || disjoint(box_of(polygon), box_of(convex))) return {};
  Convex out = polygon;
  const std::size_t n = convex.v.size();
  for (std::size_t i = 0; i < n && !empty(out); ++i)
    out = clip(out, edge_half_plane(convex.v[i], convex.v[(i + 1) % n]));
  return out;
}

Region subtract(const Convex& polygon, const Convex& convex, double min_area) {
  if (empty(polygon) || signed_area(polygon.v) < min_area) return {};
  if (empty(convex) || disjoint(box_of(polygon), box_of(convex))) return {polygon};
  Region out;
  Convex rest = polygon;
  const std::size_t n = convex.v.size();
  for (std::size_t i = 0; i < n; ++i) {
    HalfPlane h = edge_half_plane(convex.v[i], convex.v[(i + 1) % n]);
    if (h.a == 0.0 && h.b == 0.0) continue;  // a zero-length edge bounds nothing
    // Outside edge i and inside edges 0 .. i-1: disjoint from the others.
    Convex outside = clip(rest, HalfPlane{-h.a, -h.b, -h.c});
    if (!empty(outside) && signed_area(outside.v) >= min_area) out.push_back(std::move(outside));
    rest = clip(rest, h);
    if (empty(rest)) break;
  }
  return out;
}

Region intersect(const Region& region, const Convex& convex, double min_area) {
  Region out;
  for (const Convex& piece : region) {
    Convex c = intersect(piece, convex);
    if (!empty(c) && signed_area(c.v) >= min_area) out.push_back(std::move(c));
  }
  return out;
}

Region subtract(const Region& region, const Convex& convex, double min_area) {
  Region out;
  for (const Convex& piece : region) {
    Region r = subtract(piece, convex, min_area);
    out.insert(out.end(), std::make_move_iterator(r.begin()), std::make_move_iterator(r.end()));
  }
  return out;
}

Region intersect(const Region& a, const Region& b, double min_area) {
  Region out;
  for (const Convex& piece : b) {
    Region r = intersect(a, piece, min_area);
    out.insert(out.end(), std::make_move_iterator(r.begin()), std::make_move_iterator(r.end()));
  }
  return out;
}

Region subtract(const Region& a, const Region& b, double min_area) {
  Region out = a;
  for (const Convex& piece : b) {
    out = subtract(out, piece, min_area);
    if (out.empty()) break;
  }
  return out;
}

bool contains(const Convex& polygon, const dvec2& p) {
  const std::size_t n = polygon.v.size();
  if (n < 3) return false;
  for (std::size_t i = 0; i < n; ++i)
    if (edge_half_plane(polygon.v[i], polygon.v[(i + 1) % n]).eval(p) < 0.0) return false;
  return true;
}

bool contains(const Region& region, const dvec2& p) {
  return std::any_of(region.begin(), region.end(), [&](const Convex& c) { return contains(c, p); });
}

}  // namespace rtcl::beam
