// Procedural closed (watertight) triangle meshes with shared vertices, for
// leak tests: every edge is used by exactly two triangles, consistently wound
// (counter-clockwise seen from outside).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/geometry.hpp"

namespace rtcl::test {

// Icosahedron subdivided `levels` times, vertices projected onto the sphere
// of `radius` around the origin: 20 * 4^levels triangles, convex.
Geometry icosphere(int levels, float radius = 1.0f);

// Icosphere whose vertex i is moved to radius * (1 + amplitude * noise_i),
// noise_i uniform in [-1, 1). Not convex, but star-shaped from the origin:
// the cone from the origin over each flat triangle covers exactly its
// spherical triangle, so every ray from the origin crosses the surface once.
Geometry bumpy_sphere(int levels, float radius, float amplitude, std::uint32_t seed);

// Latitude/longitude sphere: `stacks` bands, `slices` around; the poles are
// vertices shared by `slices` triangles (high-valence fans).
Geometry uv_sphere(int stacks, int slices, float radius = 1.0f);

// The cube [-half, half]^3, each face an n x n grid of quads split into two
// triangles, diagonals alternating. With n even and half a power of two,
// every vertex coordinate is exact (multiples of 2 * half / n).
Geometry cube_grid(int n, float half = 1.0f);

// The boundary of a staircase of unit voxels: column x (0 <= x < steps) is
// steps - x voxels high (y) and `depth` deep (z), the solid spans
// [0, steps] x [0, steps] x [0, depth]. Non-convex: concave and convex edges
// at integer coordinates, faces coplanar with the step tops. Every vertex
// coordinate is an integer.
Geometry staircase(int steps, int depth);

// Each undirected edge (i < j) once.
std::vector<std::pair<std::uint32_t, std::uint32_t>> unique_edges(const Geometry& mesh);

// Triangles using each vertex.
std::vector<std::vector<std::uint32_t>> vertex_triangles(const Geometry& mesh);

// Number of edges not shared by exactly two triangles with opposite
// orientation: 0 for a closed, consistently wound mesh.
std::size_t open_edges(const Geometry& mesh);

}  // namespace rtcl::test
