#include "rtcl/scene/procedural.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <unordered_map>
#include <vector>

#include "rtcl/error.hpp"
#include "rtcl/scene/orthonormal_basis.hpp"

namespace rtcl {

namespace {

void check_levels(const char* what, int levels, int most) {
  if (levels < 0 || levels > most)
    throw Error(std::string(what) + ": levels=" + std::to_string(levels) + ": must be in [0, " +
                std::to_string(most) + "]");
}

void add_flake(Geometry& g, const glm::dvec3& centre, double radius, const glm::dvec3& up, int levels) {
  g.spheres.push_back({glm::vec3(centre), static_cast<float>(radius)});
  if (levels == 0) return;
  constexpr double pi = 3.14159265358979323846;
  glm::dvec3 t1, t2;
  orthonormal_basis(up, t1, t2);
  const double child = radius / 3.0, distance = radius + child;
  for (int k = 0; k < 9; ++k) {
    // six on the equator, three at 60 degrees of latitude between them
    double latitude = k < 6 ? 0.0 : pi / 3.0;
    double longitude = k < 6 ? k * pi / 3.0 : pi / 6.0 + (k - 6) * 2.0 * pi / 3.0;
    glm::dvec3 dir = std::cos(latitude) * (std::cos(longitude) * t1 + std::sin(longitude) * t2) +
                     std::sin(latitude) * up;
    add_flake(g, centre + distance * dir, child, dir, levels - 1);
  }
}

// Hash of an edge's end points and a seed, as a float in [-1, 1]: the
// displacement of its midpoint, the same whichever triangle splits it.
float edge_noise(std::uint32_t a, std::uint32_t b, std::uint32_t seed) {
  std::uint64_t x = (std::uint64_t(std::min(a, b)) << 32 | std::max(a, b)) ^ (std::uint64_t(seed) * 0x9e3779b97f4a7c15ull);
  x ^= x >> 33;  // the finaliser of MurmurHash3 (public domain)
  x *= 0xff51afd7ed558ccdull;
  x ^= x >> 33;
  x *= 0xc4ceb9fe1a85ec53ull;
  x ^= x >> 33;
  return static_cast<float>(static_cast<double>(x >> 11) * 0x1p-52 - 1.0);
}

}  // namespace

Geometry sphereflake(int levels) {
  check_levels("sphereflake", levels, 7);
  Geometry g;
  g.source = "sphereflake:levels=" + std::to_string(levels);
  std::size_t count = 0;
  for (int i = 0, p = 1; i <= levels; ++i, p *= 9) count += std::size_t(p);
  g.spheres.reserve(count);
  add_flake(g, glm::dvec3(0.0), 1.0, glm::dvec3(0.0, 1.0, 0.0), levels);
  return g;
}

Geometry sierpinski_tetrahedron(int levels) {
  check_levels("tetra", levels, 10);
  using Tetra = std::array<glm::vec3, 4>;
  std::vector<Tetra> tetras = {{glm::vec3(0.0f, 0.0f, 0.0f), glm::vec3(1.0f, 0.0f, 0.0f),
                                glm::vec3(0.5f, 0.0f, static_cast<float>(std::sqrt(3.0) / 2.0)),
                                glm::vec3(0.5f, static_cast<float>(std::sqrt(2.0 / 3.0)),
                                          static_cast<float>(std::sqrt(3.0) / 6.0))}};
  for (int level = 0; level < levels; ++level) {
    std::vector<Tetra> next;
    next.reserve(4 * tetras.size());
    for (const Tetra& t : tetras)
      for (int corner = 0; corner < 4; ++corner) {
        Tetra c;
        // (a + b) * 0.5 rounds the same for (a, b) and (b, a): neighbours
        // share their meeting point exactly
        for (int j = 0; j < 4; ++j) c[j] = j == corner ? t[corner] : (t[corner] + t[j]) * 0.5f;
        next.push_back(c);
      }
    tetras.swap(next);
  }
  Geometry g;
  g.source = "tetra:levels=" + std::to_string(levels);
  g.vertices.reserve(4 * tetras.size());
  g.triangles.reserve(4 * tetras.size());
  for (const Tetra& t : tetras) {
    auto base = static_cast<std::uint32_t>(g.vertices.size());
    g.vertices.insert(g.vertices.end(), t.begin(), t.end());
    g.triangles.push_back({base, base + 2, base + 1});
    g.triangles.push_back({base, base + 1, base + 3});
    g.triangles.push_back({base + 1, base + 2, base + 3});
    g.triangles.push_back({base + 2, base, base + 3});
  }
  return g;
}

Geometry fractal_mountain(int levels, std::uint32_t seed, float roughness) {
  check_levels("mount", levels, 10);
  if (!(roughness >= 0.0f) || !std::isfinite(roughness))
    throw Error("mount: roughness=" + std::to_string(roughness) + ": must be finite and >= 0");
  Geometry g;
  g.source = "mount:levels=" + std::to_string(levels);
  g.vertices = {{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 1.0f}, {0.0f, 0.0f, 1.0f}};
  std::vector<glm::uvec3> triangles = {{0, 2, 1}, {0, 3, 2}};
  float amplitude = roughness;
  for (int level = 0; level < levels; ++level) {
    amplitude *= 0.5f;
    std::unordered_map<std::uint64_t, std::uint32_t> midpoints;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      std::uint64_t key = std::uint64_t(std::min(a, b)) << 32 | std::max(a, b);
      auto [it, added] = midpoints.try_emplace(key, static_cast<std::uint32_t>(g.vertices.size()));
      if (added) {
        glm::vec3 m = (g.vertices[a] + g.vertices[b]) * 0.5f;
        m.y += amplitude * edge_noise(a, b, seed);
        g.vertices.push_back(m);
      }
      return it->second;
    };
    std::vector<glm::uvec3> next;
    next.reserve(4 * triangles.size());
    for (const glm::uvec3& t : triangles) {
      std::uint32_t ab = midpoint(t.x, t.y), bc = midpoint(t.y, t.z), ca = midpoint(t.z, t.x);
      next.insert(next.end(), {{t.x, ab, ca}, {ab, t.y, bc}, {ca, bc, t.z}, {ab, bc, ca}});
    }
    triangles.swap(next);
  }
  g.triangles = std::move(triangles);
  const float radius = 0.08f, height = roughness + radius + 0.05f;
  for (glm::vec2 p : {glm::vec2(0.3f, 0.3f), glm::vec2(0.7f, 0.35f), glm::vec2(0.45f, 0.7f), glm::vec2(0.75f, 0.75f)})
    g.spheres.push_back({glm::vec3(p.x, height, p.y), radius});
  return g;
}

Geometry random_triangle_soup(std::size_t count, std::uint32_t seed) {
  if (count == 0 || count > (std::size_t(1) << 26))
    throw Error("soup: count=" + std::to_string(count) + ": must be in [1, 67108864]");
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), centred(-0.5f, 0.5f);
  const float size = static_cast<float>(std::cbrt(1.0 / static_cast<double>(count)));
  Geometry g;
  g.source = "soup:count=" + std::to_string(count);
  g.vertices.reserve(3 * count);
  g.triangles.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    glm::vec3 c(unit(rng), unit(rng), unit(rng));
    auto base = static_cast<std::uint32_t>(g.vertices.size());
    for (int k = 0; k < 3; ++k) g.vertices.push_back(c + size * glm::vec3(centred(rng), centred(rng), centred(rng)));
    g.triangles.push_back({base, base + 1, base + 2});
  }
  return g;
}

Geometry tessellated_surface(std::size_t count) {
  if (count < 18 || count > (std::size_t(1) << 26))
    throw Error("surface: count=" + std::to_string(count) + ": must be in [18, 67108864]");
  const std::size_t nv = std::max<std::size_t>(3, std::llround(std::sqrt(static_cast<double>(count) / 8.0)));
  const std::size_t nu = std::max<std::size_t>(3, std::llround(static_cast<double>(count) / (2.0 * nv)));
  constexpr double pi = 3.14159265358979323846, ring = 1.0, tube = 0.3, bump = 0.03;
  Geometry g;
  g.source = "surface:count=" + std::to_string(count);
  g.vertices.reserve(nu * nv);
  g.triangles.reserve(2 * nu * nv);
  for (std::size_t i = 0; i < nu; ++i) {
    const double u = 2.0 * pi * static_cast<double>(i) / static_cast<double>(nu);
    for (std::size_t j = 0; j < nv; ++j) {
      const double v = 2.0 * pi * static_cast<double>(j) / static_cast<double>(nv);
      // Periodic in u and v, so the seam closes: integer frequencies only.
      const double r = tube + bump * (0.6 * std::sin(13.0 * u) * std::sin(5.0 * v) +
                                      0.4 * std::sin(41.0 * u + 3.0 * v) * std::cos(11.0 * v));
      const double w = ring + r * std::cos(v);
      g.vertices.push_back(glm::vec3(glm::dvec3(w * std::cos(u), r * std::sin(v), w * std::sin(u))));
    }
  }
  auto at = [&](std::size_t i, std::size_t j) { return static_cast<std::uint32_t>((i % nu) * nv + j % nv); };
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j) {
      g.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      g.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return g;
}

void add_stadium(Geometry& g, float scale) {
  if (!(scale > 1.0f) || !std::isfinite(scale))
    throw Error("stadium: scale=" + std::to_string(scale) + ": must be finite and > 1");
  Aabb box = g.bounds();
  glm::vec3 extent = box.extent();
  float half = 0.5f * scale * std::max({extent.x, extent.y, extent.z});
  glm::vec3 c = box.center();
  auto first = static_cast<std::uint32_t>(g.vertices.size());
  for (int i = 0; i < 8; ++i)
    g.vertices.push_back(c + half * glm::vec3(i & 1 ? 1.0f : -1.0f, i & 2 ? 1.0f : -1.0f, i & 4 ? 1.0f : -1.0f));
  const std::uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    g.triangles.push_back(glm::uvec3(first + q[0], first + q[1], first + q[2]));
    g.triangles.push_back(glm::uvec3(first + q[0], first + q[2], first + q[3]));
  }
}

}  // namespace rtcl
