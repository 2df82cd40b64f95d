// What the acceleration structures are built over: triangles (indexed) and
// analytic spheres. Primitive ids: triangles 0 .. triangle_count-1 in array
// order, then spheres.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/aabb.hpp"
#include "rtcl/error.hpp"

namespace rtcl {

struct Sphere {
  glm::vec3 center{0.0f};
  float radius = 1.0f;
};

struct Geometry {
  std::vector<glm::vec3> vertices;
  std::vector<glm::uvec3> triangles;  // indices into vertices
  std::vector<Sphere> spheres;
  std::string source = "geometry";  // named in error messages (a file path, "scene", ...)

  // Copies caller arrays: xyz = 3 floats per vertex, indices = 3 per triangle.
  static Geometry from_arrays(const float* xyz, std::size_t vertex_count, const std::uint32_t* indices,
                              std::size_t triangle_count, std::string source = "geometry");

  std::size_t primitive_count() const { return triangles.size() + spheres.size(); }
  Aabb primitive_bounds(std::size_t prim) const;
  Aabb bounds() const;
};

struct GeometryReport {
  std::size_t zero_area_triangles = 0;  // skipped by every structure; ids keep file order
};

// Whether validate tests every triangle for zero area, or leaves it to a
// caller that tests them anyway (the BVH build's pass over the triangles):
// that caller then counts them and throws empty_scene_error for a scene of
// zero-area triangles only.
enum class ZeroAreaTest { in_validate, by_caller };

// Throws Error naming geometry.source and the first offending element for:
// NaN/Inf vertex coordinates, out-of-range indices, NaN/Inf or non-positive
// sphere radius or centre, and a scene with nothing to hit (no primitive, or
// only zero-area triangles). Counts zero-area triangles (exactly zero in
// double precision); with ZeroAreaTest::by_caller it neither counts them
// nor rejects a scene of them only.
GeometryReport validate(const Geometry& geometry, ZeroAreaTest zero_area_test = ZeroAreaTest::in_validate);

// The error for a scene with nothing to hit.
Error empty_scene_error(const Geometry& geometry);

// True when the triangle with corners a, b, c has an area of exactly zero
// in double precision. Inline: the builders test every triangle, where a
// call per triangle would be a measurable share of a build.
inline bool zero_area(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const glm::dvec3 da(a), db(b), dc(c);
  const glm::dvec3 n = glm::cross(db - da, dc - da);
  return n.x == 0.0 && n.y == 0.0 && n.z == 0.0;
}
// The same test on a triangle of the geometry.
inline bool zero_area(const Geometry& geometry, std::size_t triangle) {
  const glm::uvec3& t = geometry.triangles[triangle];
  return zero_area(geometry.vertices[t.x], geometry.vertices[t.y], geometry.vertices[t.z]);
}

}  // namespace rtcl
