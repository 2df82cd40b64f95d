#include "support/reference.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <glm/glm.hpp>

namespace rtcl::test {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

glm::dvec3 origin(const Ray& r) { return {r.ox, r.oy, r.oz}; }
glm::dvec3 direction(const Ray& r) { return {r.dx, r.dy, r.dz}; }

double distance_to_segment(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b) {
  glm::dvec3 ab = b - a;
  double len2 = glm::dot(ab, ab);
  double s = len2 > 0 ? glm::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return glm::length(p - (a + s * ab));
}

}  // namespace

namespace {

// reference_intersect with the ray's tolerance given (it costs a pass over
// the scene). With inside_only, a triangle the ray's plane point falls
// outside of returns plane = false at once (its margin is not needed).
PrimHit intersect(const Geometry& g, std::uint32_t prim, const Ray& ray, const Tolerance& tol, bool inside_only) {
  PrimHit out;
  glm::dvec3 o = origin(ray), d = direction(ray);
  if (prim < g.triangles.size()) {
    const glm::uvec3& tri = g.triangles[prim];
    glm::dvec3 a(g.vertices[tri.x]), b(g.vertices[tri.y]), c(g.vertices[tri.z]);
    glm::dvec3 n = glm::cross(b - a, c - a);
    double denom = glm::dot(n, d);
    if (denom == 0.0 || glm::dot(n, n) == 0.0) return out;
    double t = glm::dot(n, a - o) / denom;
    glm::dvec3 p = o + t * d;
    // inside test by edge signs; margin = distance to the nearest edge
    double s0 = glm::dot(glm::cross(b - a, p - a), n), s1 = glm::dot(glm::cross(c - b, p - b), n),
           s2 = glm::dot(glm::cross(a - c, p - c), n);
    bool inside = s0 >= 0 && s1 >= 0 && s2 >= 0;
    if (inside_only && !inside) return out;
    out.plane = true;
    out.t = t;
    double dist = std::min({distance_to_segment(p, a, b), distance_to_segment(p, b, c), distance_to_segment(p, c, a)});
    out.margin = inside ? dist : -dist;
    return out;
  }
  const Sphere& s = g.spheres[prim - g.triangles.size()];
  glm::dvec3 cc(s.center);
  double a = glm::dot(d, d);
  double tc = glm::dot(cc - o, d) / a;
  glm::dvec3 closest = o + tc * d;
  double dist = glm::length(closest - cc);
  double r = s.radius;
  out.margin = r - dist;
  out.plane = true;
  double half = dist < r ? std::sqrt(r * r - dist * dist) / std::sqrt(a) : 0.0;
  double t0 = tc - half, t1 = tc + half;
  out.t = t0 >= ray.tmin - tol.t ? t0 : t1;
  return out;
}

}  // namespace

PrimHit reference_intersect(const Geometry& g, std::uint32_t prim, const Ray& ray) {
  return intersect(g, prim, ray, tolerance_for(g, ray), false);
}

PrimHit reference_intersect(const Geometry& g, std::uint32_t prim, const Ray& ray, const Tolerance& tolerance) {
  return intersect(g, prim, ray, tolerance, false);
}

Tolerance tolerance_in(const Aabb& box, const Ray& ray, double ulps) {
  glm::dvec3 lo(box.lower), hi(box.upper), o = origin(ray);
  double magnitude = std::max({glm::length(hi - lo), glm::length(lo), glm::length(hi), glm::length(o)});
  double space = ulps * FLT_EPSILON * magnitude;
  return {space, space / glm::length(direction(ray))};
}

namespace {

// The scene's bounds cost a pass over every primitive: the functions below
// take them computed once.

Hit closest_in(const Geometry& g, const Aabb& box, const Ray& ray) {
  Hit best{std::numeric_limits<float>::infinity(), 0.0f, 0.0f, -1};
  double best_t = kInf;
  Tolerance tol = tolerance_in(box, ray, 256.0);
  for (std::uint32_t p = 0; p < g.primitive_count(); ++p) {
    if (p < g.triangles.size() && zero_area(g, p)) continue;
    PrimHit h = intersect(g, p, ray, tol, true);
    if (!h.plane || h.margin <= tol.space) continue;
    if (h.t < ray.tmin + tol.t || h.t > ray.tmax - tol.t) continue;
    if (h.t < best_t) {
      best_t = h.t;
      best.t = static_cast<float>(h.t);
      best.prim = static_cast<int>(p);
    }
  }
  return best;
}

// The device's (u, v) against the reference (Hit, kernels/shared/
// query_layouts.h): for a triangle (v0, v1, v2) the point (1-u-v) v0 + u v1
// + v v2 lies within the spatial tolerance of the reference's hit point on
// the triangle's plane (the tolerance t is held to, times |d|); a sphere's
// u and v are 0. `h` is the reference's intersection with the device's
// primitive.
std::string judge_barycentrics(const Geometry& g, std::uint32_t prim, const Ray& ray, const Hit& device,
                               const PrimHit& h, const Tolerance& tol) {
  std::ostringstream why;
  why.precision(9);
  if (prim >= g.triangles.size()) {
    if (device.u != 0.0f || device.v != 0.0f) why << "device sphere hit with u=" << device.u << " v=" << device.v << " (must be 0)";
    return why.str();
  }
  const glm::uvec3& tri = g.triangles[prim];
  glm::dvec3 a(g.vertices[tri.x]), b(g.vertices[tri.y]), c(g.vertices[tri.z]);
  double u = device.u, v = device.v;
  glm::dvec3 from_uv = (1.0 - u - v) * a + u * b + v * c;
  glm::dvec3 reference = origin(ray) + h.t * direction(ray);
  double off = glm::length(from_uv - reference);
  if (!(off <= tol.space))
    why << "device hit prim " << prim << " with u=" << device.u << " v=" << device.v << ": that point is " << off
        << " from the reference's hit point (tolerance " << tol.space << ")";
  return why.str();
}

// judge, with the ray's reference_closest when `known` is not null.
std::string judge_in(const Geometry& g, const Aabb& box, const Ray& ray, const Hit& device, Query query,
                     const Hit* known) {
  Tolerance tol = tolerance_in(box, ray, 256.0);
  std::ostringstream why;
  double device_t = device.prim >= 0 ? static_cast<double>(device.t) : kInf;
  if (device.prim >= 0) {
    if (device.prim >= static_cast<int>(g.primitive_count())) {
      why << "device prim " << device.prim << " out of range";
      return why.str();
    }
    PrimHit h = intersect(g, static_cast<std::uint32_t>(device.prim), ray, tol, false);
    if (!h.plane || h.margin < -tol.space || std::abs(h.t - device_t) > tol.t) {
      why << "device hit prim " << device.prim << " at t=" << device.t << " but the reference has plane=" << h.plane
          << " t=" << h.t << " margin=" << h.margin << " (tolerance " << tol.space << ")";
      return why.str();
    }
    if (device_t < ray.tmin - tol.t || device_t > ray.tmax + tol.t) {
      why << "device t=" << device.t << " outside [" << ray.tmin << ", " << ray.tmax << "]";
      return why.str();
    }
    std::string uv = judge_barycentrics(g, static_cast<std::uint32_t>(device.prim), ray, device, h, tol);
    if (!uv.empty()) return uv;
  } else if (!std::isinf(device.t) || device.prim != -1 || device.u != 0.0f || device.v != 0.0f) {
    why << "miss must be t=inf prim=-1 u=v=0, got t=" << device.t << " prim=" << device.prim << " u=" << device.u
        << " v=" << device.v;
    return why.str();
  }
  // A valid any-hit answer needs no reference: only a miss is checked against it.
  if (query == Query::any && device.prim >= 0) return "";
  Hit ref = known ? *known : closest_in(g, box, ray);
  if (ref.prim < 0) return "";
  if (query == Query::any) {
    if (device.prim < 0) {
      why << "device found no hit; reference hits prim " << ref.prim << " at t=" << ref.t;
      return why.str();
    }
    return "";
  }
  if (device_t > static_cast<double>(ref.t) + tol.t) {
    why << "device " << (device.prim < 0 ? "missed" : "hit prim " + std::to_string(device.prim) + " at t=" +
                                                          std::to_string(device.t))
        << "; reference hits prim " << ref.prim << " nearer, at t=" << ref.t;
    return why.str();
  }
  return "";
}

std::vector<std::string> judge_rays(const Geometry& g, const std::vector<Ray>& rays, const std::vector<Hit>& hits,
                                    Query query, const std::vector<Hit>* references, std::size_t* failures,
                                    std::size_t report) {
  std::vector<std::string> out;
  *failures = 0;
  Aabb box = g.bounds();
  // Each ray is judged on its own: contiguous ranges on every hardware
  // thread, the verdicts then read in ray order.
  std::vector<std::string> verdicts(rays.size());
  auto judge_range = [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i)
      verdicts[i] = judge_in(g, box, rays[i], hits[i], query, references ? &(*references)[i] : nullptr);
  };
  std::size_t threads = std::max(1u, std::thread::hardware_concurrency());
  if (rays.size() < 256) threads = 1;
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < threads; ++t)
    pool.emplace_back(judge_range, rays.size() * t / threads, rays.size() * (t + 1) / threads);
  judge_range(0, rays.size() / threads);
  for (std::thread& t : pool) t.join();
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const std::string& why = verdicts[i];
    if (why.empty()) continue;
    ++*failures;
    if (out.size() < report) {
      const Ray& r = rays[i];
      std::ostringstream s;
      s.precision(9);
      s << "ray " << i << " (o=" << r.ox << "," << r.oy << "," << r.oz << " d=" << r.dx << "," << r.dy << "," << r.dz
        << " t=[" << r.tmin << "," << r.tmax << "]): " << why;
      out.push_back(s.str());
    }
  }
  return out;
}

}  // namespace

Tolerance tolerance_for(const Geometry& g, const Ray& ray, double ulps) { return tolerance_in(g.bounds(), ray, ulps); }

Hit reference_closest(const Geometry& g, const Ray& ray) { return closest_in(g, g.bounds(), ray); }

std::vector<Hit> reference_closest_all(const Geometry& g, const std::vector<Ray>& rays) {
  Aabb box = g.bounds();
  std::vector<Hit> out;
  out.reserve(rays.size());
  for (const Ray& r : rays) out.push_back(closest_in(g, box, r));
  return out;
}

std::string judge(const Geometry& g, const Ray& ray, const Hit& device, Query query) {
  return judge_in(g, g.bounds(), ray, device, query, nullptr);
}

std::vector<std::string> judge_all(const Geometry& g, const std::vector<Ray>& rays, const std::vector<Hit>& hits,
                                   Query query, std::size_t* failures, std::size_t report) {
  return judge_rays(g, rays, hits, query, nullptr, failures, report);
}

std::vector<std::string> judge_all(const Geometry& g, const std::vector<Ray>& rays, const std::vector<Hit>& hits,
                                   Query query, const std::vector<Hit>& references, std::size_t* failures,
                                   std::size_t report) {
  if (references.size() != rays.size()) throw std::invalid_argument("judge_all: one reference per ray expected");
  return judge_rays(g, rays, hits, query, &references, failures, report);
}

DoubleAnswer double_closest(const Geometry& g, const Ray& ray, double scene_size) {
  const Tolerance tolerance = tolerance_for(g, ray);
  // Double precision decides far closer than `space` to a boundary: its
  // rounding error is ~1e-16 of the coordinates' magnitude (the scene's and
  // the origin's, tolerance_for's), kept below by 1e-12 of it.
  const double magnitude = tolerance.space / (256.0 * FLT_EPSILON);
  const double space = std::max(1e-9 * scene_size, 1e-12 * magnitude);
  const double slack = space / glm::length(direction(ray));  // the same in t
  // A sphere's near root counts from tmin - slack (else its far root): an
  // origin just inside a sphere meets its far root, which double decides.
  const Tolerance roots{space, slack};
  DoubleAnswer best;
  double best_t = kInf;
  bool ambiguous = false;
  std::vector<double> near;  // t of candidates within `space` of their boundary, or `slack` of tmin or tmax
  for (std::uint32_t p = 0; p < g.primitive_count(); ++p) {
    if (p < g.triangles.size() && zero_area(g, p)) continue;
    PrimHit h = reference_intersect(g, p, ray, roots);
    if (!h.plane || h.margin < -space) continue;
    if (h.t < ray.tmin - slack || h.t > ray.tmax + slack) continue;
    if (h.margin <= space || h.t <= ray.tmin + slack || h.t >= ray.tmax - slack) {
      near.push_back(h.t);
      continue;
    }
    if (h.t < best_t) {
      best_t = h.t;
      best.prim = static_cast<int>(p);
    }
  }
  best.t = best_t;
  for (double t : near)
    if (t <= best_t + slack) ambiguous = true;
  if (best.prim >= 0)
    for (std::uint32_t p = 0; p < g.primitive_count(); ++p) {
      if (static_cast<int>(p) == best.prim || (p < g.triangles.size() && zero_area(g, p))) continue;
      PrimHit h = reference_intersect(g, p, ray, roots);
      if (h.plane && h.margin > space && std::abs(h.t - best_t) <= slack) ambiguous = true;
    }
  if (ambiguous) best.prim = -2;
  return best;
}

AnswerErrors answer_errors(const Geometry& g, const std::vector<Ray>& rays, const std::vector<Hit>& hits, Query query,
                           const std::vector<Hit>& references) {
  if (references.size() != rays.size() || hits.size() != rays.size())
    throw std::invalid_argument("answer_errors: one hit and one reference per ray expected");
  AnswerErrors out;
  Aabb box = g.bounds();
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Ray& ray = rays[i];
    const Hit& hit = hits[i];
    Tolerance unit = tolerance_in(box, ray, 1.0), tol = tolerance_in(box, ray, 256.0);
    const Hit& ref = references[i];
    if (ref.prim >= 0) {
      ++out.reference_hits;
      bool through = hit.prim < 0 || (query == Query::closest && double(hit.t) > double(ref.t) + tol.t);
      if (through) ++out.leaks;
    }
    if (hit.prim < 0) continue;
    ++out.hits;
    if (hit.prim >= static_cast<int>(g.primitive_count())) {
      ++out.false_hits;
      continue;
    }
    auto prim = static_cast<std::uint32_t>(hit.prim);
    PrimHit h = intersect(g, prim, ray, tol, false);
    double t_error = h.plane ? std::abs(h.t - double(hit.t)) / unit.t : kInf;
    if (!h.plane || h.margin < -tol.space || t_error > 256.0) ++out.false_hits;
    if (!h.plane) continue;
    out.max_t_error_ulps = std::max(out.max_t_error_ulps, t_error);
    if (prim < g.triangles.size()) {
      const glm::uvec3& tri = g.triangles[prim];
      glm::dvec3 a(g.vertices[tri.x]), b(g.vertices[tri.y]), c(g.vertices[tri.z]);
      double u = hit.u, v = hit.v;
      double off = glm::length((1.0 - u - v) * a + u * b + v * c - (origin(ray) + h.t * direction(ray)));
      out.max_uv_error_ulps = std::max(out.max_uv_error_ulps, std::isnan(off) ? kInf : off / unit.space);
    }
  }
  return out;
}

}  // namespace rtcl::test
