// Scenes generated at a chosen size, after Eric Haines' Standard Procedural
// Database (SPD, 1987): the benchmark's scalable inputs, with their
// primitive counts in closed form. Every generator is deterministic (a
// fixed seed gives the same geometry on every machine) and its output
// passes validate().
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "rtcl/geometry.hpp"

namespace rtcl {

// Sphereflake: a unit sphere at the origin carrying nine spheres of a third
// of its radius that touch it (six around its equator, three above at 60
// degrees of latitude), each carrying nine of its own turned away from its
// parent, `levels` times: sum of 9^i for i = 0 .. levels spheres (levels 4:
// 7,381, the SPD's default). Analytic spheres only. levels <= 7.
Geometry sphereflake(int levels);

// Sierpinski tetrahedron: a regular tetrahedron of edge 1 replaced `levels`
// times by the four half-size tetrahedra at its corners: 4^(levels + 1)
// triangles whose total area is the first tetrahedron's at every level
// (each step quarters the area of four copies). Neighbouring tetrahedra
// meet in single points, shared exactly. levels <= 11.
Geometry sierpinski_tetrahedron(int levels);

// Fractal mountain: a square of side 1 in the xz-plane split into two
// triangles, each subdivided into four `levels` times with every new edge
// midpoint raised by a random offset that halves per level (midpoint
// displacement; shared edges get one midpoint, so the surface has no
// cracks): 2 * 4^levels triangles, heights within +-roughness of 0. Plus
// four spheres floating above it (the SPD's mount has glass spheres; a
// renderer gives them a glass material). levels <= 11.
Geometry fractal_mountain(int levels, std::uint32_t seed = 1, float roughness = 0.25f);

// A random soup: `count` triangles with centres uniform in the unit cube and
// vertices within count^(-1/3) of their centre (so that the soup's density
// stays the same at every size: about one triangle per cell of side
// count^(-1/3)), up to 2^26.
Geometry random_triangle_soup(std::size_t count, std::uint32_t seed = 1);

// A tessellated surface: a torus (ring radius 1, tube radius 0.3, about the
// y axis) whose tube radius is displaced by a smooth closed-form bump field
// (+-0.03), as a closed connected mesh of nu x nv grid quads, two triangles
// each, every vertex shared by six triangles: the realistic large mesh next
// to the soup. nv = max(3, round(sqrt(count / 8))) around the tube and
// nu = max(3, round(count / (2 nv))) around the ring, so 2 nu nv triangles,
// within 0.1% of `count` from 1M up; count in [18, 2^26].
Geometry tessellated_surface(std::size_t count);

// Appends a closed box around `geometry` (12 triangles facing inwards),
// `scale` (> 1) times its largest side and centred on it: the "teapot in a
// stadium" around any geometry, a scene whose primitives fill a tiny part
// of its box.
void add_stadium(Geometry& geometry, float scale);

}  // namespace rtcl
