// The renderer's two-level path (docs/scenes-and-instances.md, "Scene
// files and the renderer"): a SceneDescription whose meshes share shapes
// is traced through an rtcl::Scene instead of being flattened. Each shape
// is one Scene mesh (built once), the still spheres one more mesh and the
// moving spheres instances of a unit sphere; every scene object is one
// instance, its user id its index here (the object index the shade kernel
// reads). Shading keeps each shape's records once, in object space
// (ShadeTriangle, ShadeSphere), and one ShadeInstance per object.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/device.hpp"
#include "rtcl/render/render_layouts.hpp"
#include "rtcl/scene.hpp"
#include "rtcl/scene/scene_description.hpp"

namespace rtcl {

// scene.lights with each emissive light expanded over the emitting
// triangles of every object, as expand_emissive_lights(scene, flatten(scene))
// gives them (each object that places an emitting mesh lights the scene
// with triangles of its own), at the camera's shutter open. Throws Error
// when an emitting object moves during the shutter, or when an emissive
// light finds no emitting triangle.
std::vector<Light> instanced_lights(const SceneDescription& scene);

class InstancedScene {
 public:
  // Builds the Scene of `scene` at the camera's shutter and uploads the
  // shading records. `accel_name` must name a structure of the BVH family
  // (the bottom levels); another is refused with an Error naming it
  // ("Renderer accel ..."). Throws Error for a scene that flatten() or
  // check_motion() refuses.
  InstancedScene(const Device& device, const SceneDescription& scene, std::string_view accel_name,
                 const AccelConfig& config);

  // The moving objects placed for the shutter [open, close] (keyframe
  // times) and committed: the top level is rebuilt, no bottom level. The
  // ShadeInstance records are uploaded again. Throws Error (naming the
  // object's motion key) when a moving object's blend becomes singular in
  // the interval; the scene then stays as it was.
  CommitStats set_shutter(double open, double close);

  const Scene& scene() const { return *scene_; }
  bool moving() const { return moving_; }
  // The objects' shading records on the device (ShadeInstance, one per
  // object) and the meshes' (ShadeTriangle and ShadeSphere, each mesh once).
  const cl::Buffer& instances() const { return instances_; }
  const cl::Buffer& triangles() const { return triangles_; }
  const cl::Buffer& spheres() const { return spheres_; }
  std::size_t shading_bytes() const { return shading_bytes_; }
  // The material of primitive `prim` of object `object` (a hit's).
  std::uint32_t material(std::uint32_t object, std::int32_t prim) const;
  // The used materials' indices, whether spheres are present.
  const std::vector<std::uint32_t>& used_materials() const { return used_materials_; }
  bool has_spheres() const { return has_spheres_; }

 private:
  // An object: a mesh (index into scene.meshes) or a sphere group.
  struct Object {
    enum Kind { mesh, still_spheres, moving_sphere } kind = mesh;
    std::size_t index = 0;   // scene.meshes or scene.spheres (moving_sphere)
    std::uint32_t bottom = 0;  // index into bottoms_
    InstanceId id;
  };
  struct Bottom {
    MeshId id;
    std::uint32_t first_triangle = 0, first_sphere = 0, triangle_count = 0;
    std::vector<std::uint32_t> materials;  // per primitive: triangles, then spheres
  };

  // The object's transforms at keyframe times open and close.
  void place(const Object& o, double open, double close, Transform& at_open, Transform& at_close) const;
  ShadeInstance record(const Object& o, const Transform& at_open, const Transform& at_close) const;

  Device device_;
  SceneDescription source_;  // the scene (shapes shared, not copied)
  std::unique_ptr<Scene> scene_;
  std::vector<Object> objects_;
  std::vector<Bottom> bottoms_;
  std::vector<ShadeInstance> records_;
  cl::Buffer instances_, triangles_, spheres_;
  std::size_t shading_bytes_ = 0;
  std::vector<std::uint32_t> used_materials_;
  bool has_spheres_ = false;
  bool moving_ = false;
};

}  // namespace rtcl
