// A scene as the shade kernel reads it: per-primitive shading records (in
// primitive-id order), materials and lights on the device, and the -D options
// that specialise the renderer's kernels to the scene.
#pragma once

#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "rtcl/device.hpp"
#include "rtcl/scene/scene_description.hpp"

namespace rtcl {

class InstancedScene;

struct DeviceScene {
  cl::Buffer triangles;  // ShadeTriangle per triangle id
  cl::Buffer spheres;    // ShadeSphere per sphere (id - triangle_count); a placeholder when none
  cl::Buffer materials;  // DeviceMaterial
  cl::Buffer lights;     // DeviceLight; a placeholder when none
  // A moving scene's primitives at shutter close (triangles, spheres as
  // above; those above are at open); empty for a static scene.
  cl::Buffer triangles_close, spheres_close;
  std::uint32_t triangle_count = 0, sphere_count = 0, light_count = 0;
  // RTCL_LIGHT_COUNT=n always; RTCL_HAS_SPHERES with spheres;
  // RTCL_HAS_REFLECTION when some primitive's material has kr > 0 or kt > 0;
  // RTCL_HAS_REFRACTION when some primitive's material has kt > 0;
  // RTCL_HAS_AREA_LIGHTS with a quad, disc or sphere light; RTCL_HAS_GLOSSY
  // when some primitive's reflecting material has roughness > 0;
  // RTCL_HAS_MOTION for a moving scene (upload_scene with `close`).
  std::vector<std::string> defines;
  // Of the camera-ray kernel: RTCL_HAS_LENS when the camera has an aperture.
  std::vector<std::string> generate_defines;
};

std::vector<std::string> shade_defines(const SceneDescription& scene, const FlatScene& flat);
// The same from the materials the primitives use and whether any is a sphere.
std::vector<std::string> shade_defines(const SceneDescription& scene, const std::set<std::uint32_t>& used_materials,
                                       bool spheres);
std::vector<std::string> generate_defines(const SceneDescription& scene);
// `flat`: the primitives (at shutter open when the scene moves); `close`:
// the same primitives at shutter close, for a moving scene only.
DeviceScene upload_scene(const Device& device, const SceneDescription& scene, const FlatScene& flat,
                         const FlatScene* close = nullptr);
// The two-level path's (instanced_scene.hpp): materials, lights and defines
// of `scene` (its emissive lights expanded); triangles and spheres are the
// InstancedScene's records. Defines RTCL_HAS_INSTANCES, and
// RTCL_HAS_MOVING_INSTANCES when an object moves.
DeviceScene upload_instanced_scene(const Device& device, const SceneDescription& scene, const InstancedScene& instanced);

}  // namespace rtcl
