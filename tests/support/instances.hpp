// References for two-level scenes (rtcl/scene.hpp): the world-space copy of
// a mesh's instances as one flat Geometry, transformed in double and
// rounded to float once, for brute-force and double-precision judging.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/geometry.hpp"
#include "rtcl/scene.hpp"

namespace rtcl::test {

// x -> A x + t of the transform, in double.
glm::dvec3 apply(const Transform& transform, const glm::dvec3& point);

// The element-wise blend (1 - time) * open + time * close, in double, as a
// transform rounded to float (the moving instance's transform at `time`).
Transform blend(const Transform& open, const Transform& close, double time);

// Mesh `mesh` under each transform, appended in order into one geometry:
// instance k's triangle p is the flat triangle first[k] + p (spheres are
// not supported). Vertices are the double images rounded to float.
struct FlatInstances {
  Geometry geometry;
  std::vector<std::uint32_t> first;  // first flat triangle of each instance
  std::vector<Aabb> boxes;           // each instance's world box (its flat vertices)
};
FlatInstances flatten_instances(const Geometry& mesh, const std::vector<Transform>& transforms);

// A hit of instance `instance` (an index into the transforms), primitive
// `prim` of its mesh, as the flat copy's hit.
Hit flat_hit(const FlatInstances& flat, std::uint32_t instance, const Hit& hit);

}  // namespace rtcl::test
