#include "rtcl/geometry.hpp"

#include <cmath>
#include <vector>

#include "rtcl/error.hpp"
#include "rtcl/parallel.hpp"

namespace rtcl {

Geometry Geometry::from_arrays(const float* xyz, std::size_t vertex_count, const std::uint32_t* indices,
                               std::size_t triangle_count, std::string source) {
  Geometry g;
  g.source = std::move(source);
  if ((vertex_count > 0 && !xyz) || (triangle_count > 0 && !indices))
    throw Error(g.source + ": null vertex or index array");
  g.vertices.resize(vertex_count);
  for (std::size_t i = 0; i < vertex_count; ++i) g.vertices[i] = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
  g.triangles.resize(triangle_count);
  for (std::size_t i = 0; i < triangle_count; ++i)
    g.triangles[i] = {indices[3 * i], indices[3 * i + 1], indices[3 * i + 2]};
  return g;
}

Aabb Geometry::primitive_bounds(std::size_t prim) const {
  Aabb b;
  if (prim < triangles.size()) {
    const glm::uvec3& t = triangles[prim];
    b.grow(vertices[t.x]);
    b.grow(vertices[t.y]);
    b.grow(vertices[t.z]);
  } else {
    const Sphere& s = spheres[prim - triangles.size()];
    b.lower = s.center - glm::vec3(s.radius);
    b.upper = s.center + glm::vec3(s.radius);
  }
  return b;
}

Aabb Geometry::bounds() const {
  Aabb b;
  for (std::size_t i = 0; i < primitive_count(); ++i) b.grow(primitive_bounds(i));
  return b;
}

namespace {
bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Vertices or triangles per host thread in validate (parallel.hpp).
constexpr std::size_t kValidatePartMin = 16384;
}  // namespace

GeometryReport validate(const Geometry& g, ZeroAreaTest zero_area_test) {
  GeometryReport report;
  for_each_part(g.vertices.size(), part_count(g.vertices.size(), 0, kValidatePartMin),
                [&](unsigned, std::size_t begin, std::size_t end) {
                  for (std::size_t i = begin; i < end; ++i)
                    if (!finite(g.vertices[i]))
                      throw Error(g.source + ": vertex " + std::to_string(i) + " has a NaN or infinite coordinate");
                });
  const unsigned parts = part_count(g.triangles.size(), 0, kValidatePartMin);
  std::vector<std::size_t> zero_area_counts(parts, 0);
  for_each_part(g.triangles.size(), parts, [&](unsigned part, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const glm::uvec3& t = g.triangles[i];
      for (int k = 0; k < 3; ++k)
        if (t[k] >= g.vertices.size())
          throw Error(g.source + ": triangle " + std::to_string(i) + " uses vertex index " + std::to_string(t[k]) +
                      ", but there are only " + std::to_string(g.vertices.size()) + " vertices");
      if (zero_area_test == ZeroAreaTest::in_validate && zero_area(g, i)) ++zero_area_counts[part];
    }
  });
  for (std::size_t count : zero_area_counts) report.zero_area_triangles += count;
  for (std::size_t i = 0; i < g.spheres.size(); ++i) {
    const Sphere& s = g.spheres[i];
    if (!finite(s.center) || !std::isfinite(s.radius) || !(s.radius > 0.0f))
      throw Error(g.source + ": sphere " + std::to_string(i) + " needs a finite centre and a positive radius");
  }
  if (g.primitive_count() == report.zero_area_triangles) throw empty_scene_error(g);
  return report;
}

Error empty_scene_error(const Geometry& g) {
  return Error(g.source + ": empty scene: no triangle with non-zero area and no sphere");
}

}  // namespace rtcl
