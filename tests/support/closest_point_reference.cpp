#include "support/closest_point_reference.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace rtcl::test {

namespace {

// Ericson 5.1.5 in double; u, v weigh b and c.
PointPrim closest_on_triangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  PointPrim r;
  auto done = [&](const glm::dvec3& q, double u, double v) {
    r.point = q;
    r.u = u;
    r.v = v;
    r.distance = glm::length(p - q);
    return r;
  };
  const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return done(a, 0.0, 0.0);
  const glm::dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return done(b, 1.0, 0.0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    return done(a + v * ab, v, 0.0);
  }
  const glm::dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return done(c, 0.0, 1.0);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);
    return done(a + w * ac, 0.0, w);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return done(b + w * (c - b), 1.0 - w, w);
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return done(a + ab * v + ac * w, v, w);
}

}  // namespace

PointPrim reference_point_prim(const Geometry& geometry, std::uint32_t prim, const glm::dvec3& p) {
  if (prim < geometry.triangles.size()) {
    const glm::uvec3& t = geometry.triangles[prim];
    return closest_on_triangle(p, glm::dvec3(geometry.vertices[t.x]), glm::dvec3(geometry.vertices[t.y]),
                               glm::dvec3(geometry.vertices[t.z]));
  }
  const Sphere& s = geometry.spheres[prim - geometry.triangles.size()];
  const glm::dvec3 c(s.center);
  const double r = s.radius;
  const double len = glm::length(p - c);
  PointPrim out;
  out.point = len == 0.0 ? c + glm::dvec3(r, 0.0, 0.0) : c + (p - c) * (r / len);
  out.distance = std::abs(len - r);
  return out;
}

ReferencePoint reference_closest_point(const Geometry& geometry, const glm::dvec3& p, double max_distance) {
  ReferencePoint best;
  best.distance = std::numeric_limits<double>::infinity();
  const auto count = static_cast<std::uint32_t>(geometry.primitive_count());
  for (std::uint32_t prim = 0; prim < count; ++prim) {
    if (prim < geometry.triangles.size() && zero_area(geometry, prim)) continue;
    const double d = reference_point_prim(geometry, prim, p).distance;
    if (d <= max_distance && d < best.distance) {
      best.distance = d;
      best.prim = static_cast<std::int32_t>(prim);
    }
  }
  return best;
}

std::vector<ReferencePoint> reference_closest_points(const Geometry& geometry, const std::vector<glm::vec3>& points,
                                                     double max_distance) {
  std::vector<ReferencePoint> out;
  out.reserve(points.size());
  for (const glm::vec3& p : points) out.push_back(reference_closest_point(geometry, glm::dvec3(p), max_distance));
  return out;
}

double closest_point_tolerance(const Aabb& bounds, const glm::dvec3& p, double ulps) {
  const glm::dvec3 lo(bounds.lower), hi(bounds.upper);
  double scale = glm::length(hi - lo);
  scale = std::max({scale, std::abs(lo.x), std::abs(lo.y), std::abs(lo.z), std::abs(hi.x), std::abs(hi.y),
                    std::abs(hi.z), std::abs(p.x), std::abs(p.y), std::abs(p.z)});
  return ulps * std::ldexp(1.0, -24) * scale;
}

std::string judge_closest_point(const Geometry& geometry, const Aabb& bounds, const glm::dvec3& p,
                                const PointHit& device, const ReferencePoint& reference, double max_distance) {
  const double tol = closest_point_tolerance(bounds, p);
  std::ostringstream why;
  why.precision(9);
  if (device.prim < 0) {
    const bool miss_record = std::isinf(device.distance) && device.distance > 0 && std::isnan(device.x) &&
                             std::isnan(device.y) && std::isnan(device.z) && device.u == 0.0f && device.v == 0.0f &&
                             device.prim == -1 && device.reserved == 0;
    if (!miss_record) return "malformed miss record";
    if (reference.prim < 0 || reference.distance >= max_distance - tol) return "";
    why << "miss, reference prim " << reference.prim << " at " << reference.distance << " (max_distance "
        << max_distance << ")";
    return why.str();
  }
  if (static_cast<std::size_t>(device.prim) >= geometry.primitive_count()) return "prim out of range";
  if (device.reserved != 0) return "reserved field not 0";
  if (reference.prim < 0 && !(device.distance <= max_distance && max_distance - tol <= device.distance)) {
    why << "hit prim " << device.prim << " at " << device.distance << " where the reference has none within "
        << max_distance;
    return why.str();
  }
  if (!(device.distance <= max_distance)) return "hit beyond max_distance";
  const double d = device.distance;
  if (reference.prim >= 0 && !(std::abs(d - reference.distance) <= tol)) {
    why << "distance " << d << ", reference " << reference.distance << " (prim " << reference.prim << "), tolerance "
        << tol;
    return why.str();
  }
  const PointPrim own = reference_point_prim(geometry, static_cast<std::uint32_t>(device.prim), p);
  if (reference.prim >= 0 && !(own.distance <= reference.distance + tol)) {
    why << "prim " << device.prim << " lies at " << own.distance << ", reference prim " << reference.prim << " at "
        << reference.distance;
    return why.str();
  }
  const glm::dvec3 q(device.x, device.y, device.z);
  if (!(glm::length(q - own.point) <= tol)) {
    why << "point (" << q.x << ", " << q.y << ", " << q.z << ") is " << glm::length(q - own.point)
        << " from prim " << device.prim << "'s nearest point, tolerance " << tol;
    return why.str();
  }
  if (!(std::abs(glm::length(p - q) - d) <= tol)) {
    why << "point at " << glm::length(p - q) << " from the query, distance says " << d;
    return why.str();
  }
  if (static_cast<std::size_t>(device.prim) < geometry.triangles.size()) {
    const glm::uvec3& t = geometry.triangles[static_cast<std::size_t>(device.prim)];
    const double u = device.u, v = device.v;
    const glm::dvec3 bary = (1.0 - u - v) * glm::dvec3(geometry.vertices[t.x]) +
                            u * glm::dvec3(geometry.vertices[t.y]) + v * glm::dvec3(geometry.vertices[t.z]);
    if (!(glm::length(bary - q) <= tol) || u < 0.0 || v < 0.0 || u + v > 1.0 + 1e-6) {
      why << "barycentrics (" << u << ", " << v << ") give a point " << glm::length(bary - q) << " from (x, y, z)";
      return why.str();
    }
  } else if (device.u != 0.0f || device.v != 0.0f) {
    return "sphere hit with u, v not 0";
  }
  return "";
}

std::vector<std::string> judge_closest_points(const Geometry& geometry, const std::vector<glm::vec3>& points,
                                              const std::vector<PointHit>& device,
                                              const std::vector<ReferencePoint>& reference, std::size_t* failures,
                                              double max_distance, std::size_t report) {
  const Aabb bounds = geometry.bounds();
  std::vector<std::string> out;
  *failures = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::string why = judge_closest_point(geometry, bounds, glm::dvec3(points[i]), device[i], reference[i], max_distance);
    if (why.empty()) continue;
    ++*failures;
    if (out.size() < report) out.push_back("point " + std::to_string(i) + ": " + why);
  }
  return out;
}

}  // namespace rtcl::test
