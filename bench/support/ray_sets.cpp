#include "bench/support/ray_sets.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "rtcl/error.hpp"
#include "rtcl/scene/orthonormal_basis.hpp"
#include "rtcl/shared/render_layouts.h"  // rtcl_hash

namespace rtcl::bench {

namespace {

constexpr float infinity = std::numeric_limits<float>::infinity();

Ray make_ray(const glm::vec3& o, const glm::vec3& d, float tmin, float tmax) {
  return Ray{o.x, o.y, o.z, d.x, d.y, d.z, tmin, tmax};
}

float unit_float(std::uint32_t bits) { return static_cast<float>(bits >> 8) * 0x1p-24f; }  // [0, 1)

// Cosine-weighted direction about n (Malley's method: a uniform point on the
// unit disc lifted to the hemisphere).
glm::vec3 cosine_direction(const glm::vec3& n, float u1, float u2) {
  float r = std::sqrt(u1), phi = 6.28318530718f * u2;
  glm::vec3 t1, t2;
  orthonormal_basis(n, t1, t2);
  glm::vec3 d = r * std::cos(phi) * t1 + r * std::sin(phi) * t2 + std::sqrt(std::max(0.0f, 1.0f - u1)) * n;
  return glm::normalize(d);
}

// The hit point and the geometric normal there (not yet facing the ray).
void surface_point(const Geometry& geometry, const Ray& ray, const Hit& hit, glm::vec3& p, glm::vec3& n) {
  auto prim = static_cast<std::size_t>(hit.prim);
  if (prim < geometry.triangles.size()) {
    const glm::uvec3& tri = geometry.triangles[prim];
    glm::vec3 v0 = geometry.vertices[tri.x], v1 = geometry.vertices[tri.y], v2 = geometry.vertices[tri.z];
    p = (1.0f - hit.u - hit.v) * v0 + hit.u * v1 + hit.v * v2;
    n = glm::normalize(glm::cross(v1 - v0, v2 - v0));
    return;
  }
  const Sphere& sphere = geometry.spheres[prim - geometry.triangles.size()];
  p = glm::vec3(ray.ox, ray.oy, ray.oz) + hit.t * glm::vec3(ray.dx, ray.dy, ray.dz);
  n = glm::normalize(p - sphere.center);
}

}  // namespace

std::vector<Ray> primary_rays(const Camera& camera, int width, int height) {
  glm::vec3 forward = glm::normalize(camera.target - camera.eye);
  glm::vec3 right = glm::normalize(glm::cross(forward, camera.up));
  glm::vec3 up = glm::cross(right, forward);
  float half_h = std::tan(0.5f * glm::radians(camera.fov_y_deg));
  float half_w = half_h * static_cast<float>(width) / static_cast<float>(height);
  std::vector<Ray> rays;
  rays.reserve(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      float sx = (2.0f * (static_cast<float>(x) + 0.5f) / static_cast<float>(width) - 1.0f) * half_w;
      float sy = (1.0f - 2.0f * (static_cast<float>(y) + 0.5f) / static_cast<float>(height)) * half_h;
      rays.push_back(make_ray(camera.eye, glm::normalize(forward + sx * right + sy * up), 0.0f, infinity));
    }
  return rays;
}

float spawn_offset(const glm::vec3& point, float scene_extent) {
  float magnitude = std::max({std::abs(point.x), std::abs(point.y), std::abs(point.z)});
  return 1e-4f * std::max(magnitude, 1e-2f * scene_extent);
}

SecondaryRays secondary_rays(const Geometry& geometry, std::span<const Ray> primary, std::span<const Hit> hits,
                             const glm::vec3& light) {
  glm::vec3 extent = geometry.bounds().extent();
  float scene_extent = std::max({extent.x, extent.y, extent.z});
  SecondaryRays out;
  std::size_t n = std::min(primary.size(), hits.size());
  for (std::size_t i = 0; i < n; ++i) {
    const Hit& hit = hits[i];
    if (hit.prim < 0) continue;
    if (static_cast<std::size_t>(hit.prim) >= geometry.primitive_count())
      throw Error("primary hit " + std::to_string(i) + " names primitive " + std::to_string(hit.prim) +
                  ", beyond the " + std::to_string(geometry.primitive_count()) + " primitives of " +
                  geometry.source);
    const Ray& r = primary[i];
    glm::vec3 p, normal;
    surface_point(geometry, r, hit, p, normal);
    if (glm::dot(normal, glm::vec3(r.dx, r.dy, r.dz)) > 0.0f) normal = -normal;
    glm::vec3 origin = p + spawn_offset(p, scene_extent) * normal;
    out.shadow.push_back(make_ray(origin, light - origin, 0.0f, 1.0f));
    auto pixel = static_cast<std::uint32_t>(i);
    float u1 = unit_float(rtcl_hash(2u * pixel + 0x9e3779b9u)), u2 = unit_float(rtcl_hash(2u * pixel + 1u + 0x9e3779b9u));
    out.diffuse.push_back(make_ray(origin, cosine_direction(normal, u1, u2), 0.0f, infinity));
  }
  return out;
}

}  // namespace rtcl::bench
