// The benchmark scenes: the shared meshes with one fixed pinhole camera and
// one point light each (used by bench/ and `rtcl bench`), and the camera
// rule for scenes without one (procedural scenes): every benchmark that
// names a scene traces the same rays.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/aabb.hpp"

namespace rtcl::bench {

// Pinhole camera; square image, vertical field of view in degrees.
struct Camera {
  glm::vec3 eye, target, up;
  float fov_y_deg;
};

struct SceneSpec {
  std::string name;  // as benchmarks name it: bunny, dragon, ...
  std::string file;  // relative to the scenes directory
  Camera camera;
  glm::vec3 light;   // point light position, scene units
  // > 0: the mesh stands inside a closed box (12 triangles) this many times
  // its largest side, centred on it: the "teapot in a stadium", a scene
  // whose primitives fill a tiny part of its box.
  float stadium = 0.0f;
  // > 0: the grid (bench/ trace/ and sweep/) traces a subset, every k-th
  // ray, at most this many, as brute force does: where it is orders of
  // magnitude slower than the BVH (the teapot in its stadium) a full set
  // would take minutes a launch.
  std::size_t grid_ray_limit = 0;
  // true: camera and light come from the loaded geometry's bounds
  // (fit_camera, fit_light); `camera` and `light` are unused.
  bool fit = false;
};

// bunny, dragon, sponza, sibenik, teapot-stadium (Google Benchmark's
// scenes, in that order), then teapot, ogre and cornell-box.
const std::vector<SceneSpec>& scene_specs();

// The spec named `name`, or nullptr.
const SceneSpec* find_scene_spec(const std::string& name);

// A camera that sees `bounds` from the front: looking at its centre from
// +z, a little above (+y), y up, 40 degree field of view, at the distance
// where the box's x-y face (plus a 10% margin) fills the view.
Camera fit_camera(const Aabb& bounds);

// A light above, to the right of and in front of the bounds' centre, one
// bounding-sphere diameter away (so that shadow rays have occluders).
glm::vec3 fit_light(const Aabb& bounds);

}  // namespace rtcl::bench
