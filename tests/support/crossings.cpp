#include "support/crossings.hpp"

#include <algorithm>
#include <cmath>
#include <thread>

#include <glm/glm.hpp>

#include "support/reference.hpp"

namespace rtcl::test {

ReferenceCrossings reference_crossings(const Geometry& g, const Aabb& bounds, const Ray& ray) {
  ReferenceCrossings out;
  Tolerance tol = tolerance_in(bounds, ray, 256.0);
  out.t_tolerance = tol.t;
  // A ray near tmin or tmax: within tolerance of the range's ends.
  auto in_range = [&](double t) {
    if (std::abs(t - ray.tmin) <= tol.t || (std::isfinite(ray.tmax) && std::abs(t - ray.tmax) <= tol.t))
      out.ambiguous = true;
    return t >= ray.tmin && t <= ray.tmax;
  };
  glm::dvec3 o(ray.ox, ray.oy, ray.oz), d(ray.dx, ray.dy, ray.dz);
  const glm::dvec3 unit = d / glm::length(d);
  for (std::uint32_t p = 0; p < g.triangles.size(); ++p) {
    if (zero_area(g, p)) continue;
    // a triangle whose bounding sphere (around vertex a) is clearly away
    // from the ray's line cannot be near it
    const glm::uvec3& tri = g.triangles[p];
    glm::dvec3 a(g.vertices[tri.x]), b(g.vertices[tri.y]), c(g.vertices[tri.z]);
    double radius = std::max(glm::length(b - a), glm::length(c - a));
    glm::dvec3 to_a = a - o;
    if (glm::length(to_a - glm::dot(to_a, unit) * unit) > 1.01 * radius + 2.0 * tol.space) continue;
    PrimHit h = reference_intersect(g, p, ray, tol);
    if (!h.plane) continue;
    bool clear_in = h.margin > tol.space, clear_out = h.margin < -tol.space;
    if (clear_out) continue;
    bool range = in_range(h.t);
    if (!clear_in) {
      if (h.t >= ray.tmin - tol.t && h.t <= ray.tmax + tol.t) out.ambiguous = true;
      continue;
    }
    if (range) out.hits.push_back({h.t, static_cast<std::int32_t>(p)});
  }
  for (std::size_t s = 0; s < g.spheres.size(); ++s) {
    const Sphere& sphere = g.spheres[s];
    glm::dvec3 c(sphere.center);
    double a = glm::dot(d, d), tc = glm::dot(c - o, d) / a;
    double dist = glm::length(o + tc * d - c), r = sphere.radius;
    if (std::abs(dist - r) <= tol.space) out.ambiguous = true;  // tangent
    if (dist >= r) continue;
    double half = std::sqrt(r * r - dist * dist) / std::sqrt(a);
    for (double t : {tc - half, tc + half})
      if (in_range(t)) out.hits.push_back({t, static_cast<std::int32_t>(g.triangles.size() + s)});
  }
  std::sort(out.hits.begin(), out.hits.end(), [](const ReferenceCrossing& x, const ReferenceCrossing& y) {
    return x.t < y.t || (x.t == y.t && x.prim < y.prim);
  });
  return out;
}

std::vector<ReferenceCrossings> reference_crossings_all(const Geometry& g, const std::vector<Ray>& rays) {
  std::vector<ReferenceCrossings> out(rays.size());
  Aabb bounds = g.bounds();
  auto range = [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) out[i] = reference_crossings(g, bounds, rays[i]);
  };
  std::size_t threads = std::max(1u, std::thread::hardware_concurrency());
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < threads; ++t)
    pool.emplace_back(range, rays.size() * t / threads, rays.size() * (t + 1) / threads);
  range(0, rays.size() / threads);
  for (std::thread& t : pool) t.join();
  return out;
}

}  // namespace rtcl::test
