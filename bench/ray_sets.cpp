#include "ray_sets.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>

#include "rtcl/error.hpp"
#include "rtcl/shared/render_layouts.h"  // rtcl_hash

namespace rtcl::bench {

namespace {

constexpr float infinity = std::numeric_limits<float>::infinity();

Ray make_ray(const glm::vec3& o, const glm::vec3& d, float tmin, float tmax) {
  return Ray{o.x, o.y, o.z, d.x, d.y, d.z, tmin, tmax};
}

float unit_float(std::uint32_t bits) { return static_cast<float>(bits >> 8) * 0x1p-24f; }  // [0, 1)

// Two tangents completing a unit normal n to an orthonormal basis, without a
// branch on the normal's direction (Duff et al., "Building an Orthonormal
// Basis, Revisited", JCGT 2017).
void tangents(const glm::vec3& n, glm::vec3& t1, glm::vec3& t2) {
  float sign = std::copysign(1.0f, n.z);
  float a = -1.0f / (sign + n.z);
  float b = n.x * n.y * a;
  t1 = glm::vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
  t2 = glm::vec3(b, sign + n.y * n.y * a, -n.y);
}

// Cosine-weighted direction about n (Malley's method: a uniform point on the
// unit disc lifted to the hemisphere).
glm::vec3 cosine_direction(const glm::vec3& n, float u1, float u2) {
  float r = std::sqrt(u1), phi = 6.28318530718f * u2;
  glm::vec3 t1, t2;
  tangents(n, t1, t2);
  glm::vec3 d = r * std::cos(phi) * t1 + r * std::sin(phi) * t2 + std::sqrt(std::max(0.0f, 1.0f - u1)) * n;
  return glm::normalize(d);
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

SecondaryRays secondary_rays(const Geometry& geometry, const RaySet& primary, const glm::vec3& light) {
  glm::vec3 extent = geometry.bounds().extent();
  float scene_extent = std::max({extent.x, extent.y, extent.z});
  SecondaryRays out;
  for (std::size_t i = 0; i < primary.reference.size(); ++i) {
    const Hit& hit = primary.reference[i];
    if (hit.prim < 0) continue;
    if (static_cast<std::size_t>(hit.prim) >= geometry.triangles.size())
      throw Error("reference hit names primitive " + std::to_string(hit.prim) + ", beyond the triangles");
    const glm::uvec3& tri = geometry.triangles[static_cast<std::size_t>(hit.prim)];
    glm::vec3 v0 = geometry.vertices[tri.x], v1 = geometry.vertices[tri.y], v2 = geometry.vertices[tri.z];
    glm::vec3 p = (1.0f - hit.u - hit.v) * v0 + hit.u * v1 + hit.v * v2;
    glm::vec3 n = glm::normalize(glm::cross(v1 - v0, v2 - v0));
    const Ray& r = primary.rays[i];
    if (glm::dot(n, glm::vec3(r.dx, r.dy, r.dz)) > 0.0f) n = -n;
    glm::vec3 origin = p + spawn_offset(p, scene_extent) * n;
    out.shadow.push_back(make_ray(origin, light - origin, 0.0f, 1.0f));
    auto pixel = static_cast<std::uint32_t>(i);
    float u1 = unit_float(rtcl_hash(2u * pixel + 0x9e3779b9u)), u2 = unit_float(rtcl_hash(2u * pixel + 1u + 0x9e3779b9u));
    out.diffuse.push_back(make_ray(origin, cosine_direction(n, u1, u2), 0.0f, infinity));
  }
  return out;
}

void write_preview(const std::string& path, const BenchScene& scene) {
  std::ofstream file(path, std::ios::binary);
  if (!file) throw Error("$RTCL_BENCH_DUMP: cannot write " + path);
  file << "P6\n" << scene.width << " " << scene.height << "\n255\n";
  std::size_t secondary = 0;
  const RaySet& primary = scene.primary;
  for (std::size_t i = 0; i < primary.rays.size(); ++i) {
    unsigned char rgb[3] = {40, 60, 110};
    const Hit& hit = primary.reference[i];
    if (hit.prim >= 0) {
      const glm::uvec3& tri = scene.geometry.triangles[static_cast<std::size_t>(hit.prim)];
      const auto& v = scene.geometry.vertices;
      glm::vec3 n = glm::normalize(glm::cross(v[tri.y] - v[tri.x], v[tri.z] - v[tri.x]));
      const Ray& r = primary.rays[i];
      float shade = std::abs(glm::dot(n, glm::vec3(r.dx, r.dy, r.dz)));
      bool shadowed = secondary < scene.shadow.reference.size() && scene.shadow.reference[secondary].prim >= 0;
      ++secondary;
      auto level = static_cast<unsigned char>(std::clamp(255.0f * (shadowed ? 0.35f : 1.0f) * shade, 0.0f, 255.0f));
      rgb[0] = rgb[1] = rgb[2] = level;
    }
    file.write(reinterpret_cast<const char*>(rgb), 3);
  }
}

}  // namespace rtcl::bench
