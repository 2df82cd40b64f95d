// The meshes and instances of one rtcl.RaycastingScene and the structures
// built over them (docs/python.md, "Instances").
//
// Each add_triangles call adds a geometry (a mesh, geometry ids in call
// order) standing where its vertices are: its own placement. add_instance
// adds one more placement of a geometry under an affine transform.
// Placements are numbered in the order they are made (a geometry's own at
// add_triangles, an instance's at add_instance); instances also have their
// own ids, 0, 1, ... in add_instance order.
//
// Until the first add_instance or update_vertices the scene is flat: the
// meshes are merged into one Geometry, mesh after mesh, under one Accel
// (placement index = geometry id; a merged primitive maps back through the
// table of each part's first primitive). From then on it is instanced: an
// rtcl::Scene holds each mesh that has something to hit once and an
// instance for each of its placements, whose user id is the placement
// index; cast_rays and test_occlusions trace it, and the other queries run
// on a flattened copy (every placement's vertices transformed into one
// merged Geometry under one Accel), built at the first such query after a
// change.
//
// Edits take effect at the first query after them (snapshot()).
#pragma once

#include <atomic>
#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <string>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/device.hpp"
#include "rtcl/geometry.hpp"
#include "rtcl/scene.hpp"

namespace rtcl::python {

// Open3D's invalid id (RaycastingScene.INVALID_ID): geometry, primitive
// and instance ids of a miss; also the instance id of a hit on a
// geometry's own placement.
inline constexpr std::uint32_t kInvalidId = 0xffffffffu;

// One geometry's triangles; immutable once made (update_vertices makes a
// new one).
struct Mesh {
  std::vector<glm::vec3> vertices;
  std::vector<glm::uvec3> triangles;
  std::vector<glm::vec3> normals;  // unit (v1 - v0) x (v2 - v0) of each triangle; 0 for zero area
  bool hittable = false;           // some triangle has a non-zero area
};

// What a hit on a placement reports, and how its normals turn.
struct Placement {
  std::uint32_t geometry = 0;
  std::uint32_t instance = kInvalidId;  // add_instance's id; kInvalidId: the geometry's own placement
  bool identity = true;                 // the transform is the identity
  Transform transform;
  // det(A) A^-T of the transform's 3x3 part A: it maps a triangle's
  // (v1 - v0) x (v2 - v0) to that of the transformed triangle.
  glm::mat3 cofactor{1.0f};
};

// A merged geometry under one Accel: the flat scene, or the instanced
// scene's flattened copy. Part k (placement k) holds primitives
// [first_prim[k], first_prim[k + 1]).
struct FlatScene {
  Geometry geometry;
  std::vector<std::uint32_t> first_prim;
  std::vector<glm::vec3> normals;  // unit face normal of each merged triangle, (v1 - v0) x (v2 - v0)
  std::unique_ptr<Accel> accel;    // null when nothing can be hit

  // The placement and its triangle of merged primitive `prim` (>= 0).
  void locate(std::int32_t prim, std::uint32_t& placement, std::uint32_t& primitive) const;
};

// What a query runs on: immutable once made, shared by the calls in flight.
struct BuiltScene {
  std::vector<Placement> placements;            // by placement index
  std::vector<std::shared_ptr<const Mesh>> meshes;  // by geometry id
  std::shared_ptr<const FlatScene> flat;        // the flat scene; null when instanced
  const Scene* scene = nullptr;                 // the instanced scene; null when flat
  bool hittable = false;                        // some placement has something to hit

  // The flat scene, or the instanced scene's flattened copy (built here at
  // the first call; thread-safe).
  std::shared_ptr<const FlatScene> flattened(const Device& device, const std::string& accel,
                                             const AccelConfig& config) const;

 private:
  mutable std::mutex flatten_mutex_;
  mutable std::shared_ptr<const FlatScene> flattened_;
};

// A BuiltScene with, for an instanced one, the rtcl::Scene held at the
// commit it was made from while the query runs.
struct SceneView {
  std::shared_ptr<const BuiltScene> built;
  std::shared_lock<std::shared_mutex> commit_hold;
  const BuiltScene* operator->() const { return built.get(); }
};

class MeshScene {
 public:
  // `accel` is a structure spec (make_accel); it and config.precision are
  // checked here (Error naming them), the structure itself is built later.
  MeshScene(Device device, std::string accel, AccelConfig config);
  ~MeshScene();

  // Adds a geometry: the mesh's checks (Error naming add_triangles and the
  // element: a NaN or infinite coordinate, an index out of range) leave the
  // scene unchanged. Returns its geometry id.
  std::uint32_t add_triangles(std::vector<glm::vec3> vertices, std::vector<glm::uvec3> triangles);

  // Adds a placement of geometry `geometry` under `transform`; returns its
  // instance id. Error (naming add_instance and the argument) for a
  // geometry that does not exist, a singular transform, or a structure
  // outside the BVH family; the scene is then unchanged.
  std::uint32_t add_instance(std::uint32_t geometry, const Transform& transform);
  // A new transform for instance `instance` (same checks as add_instance).
  void set_transform(std::uint32_t instance, const Transform& transform);
  // New vertex positions for a geometry's mesh (its vertex count; the
  // triangles stay). Error for a wrong count, a non-finite coordinate or a
  // mesh left with nothing to hit (where it had something).
  void update_vertices(std::uint32_t geometry, std::vector<glm::vec3> vertices);

  // The scene as it is now, committed or built here when it changed since
  // the last call (one at a time; concurrent callers wait). Thread-safe.
  SceneView snapshot() const;

  std::size_t geometry_count() const { return geometry_count_.load(); }
  std::size_t instance_count() const { return instance_count_.load(); }
  // Whether cast_rays reports instance_ids (after the first add_instance or
  // update_vertices).
  bool instanced() const { return instanced_.load(); }
  const Device& device() const { return device_; }
  const std::string& accel_spec() const { return accel_; }
  const AccelConfig& config() const { return config_; }

 private:
  struct GeometryEntry {
    std::shared_ptr<const Mesh> mesh;
    std::optional<MeshId> scene_mesh;  // in scene_, once instanced and hittable
    std::vector<std::uint32_t> placements;
  };
  struct PlacementEntry {
    Placement placement;
    std::optional<InstanceId> scene_instance;
  };

  // The rtcl::Scene of the current geometries and placements (for the
  // first add_instance or update_vertices).
  std::unique_ptr<Scene> make_scene(const char* call) const;
  // Adds geometry g's mesh and its placements to `scene` (nothing when it
  // has nothing to hit); the ids go to `mesh` and `instances`.
  void add_to_scene(Scene& scene, std::uint32_t id, const GeometryEntry& g, const Mesh& mesh,
                    std::optional<MeshId>& mesh_id, std::vector<std::optional<InstanceId>>& instances) const;
  // A Scene of every geometry and placement, made aside (geometry
  // `replaced` with `replacement` when that is given), with the ids of
  // each geometry's mesh and placements; adopt() makes it the scene's and
  // throws only on allocation.
  struct FreshScene {
    std::unique_ptr<Scene> scene;
    std::vector<std::optional<MeshId>> meshes;
    std::vector<std::vector<std::optional<InstanceId>>> instances;
  };
  FreshScene fresh_scene(const char* call, const Mesh* replacement = nullptr, std::uint32_t replaced = 0) const;
  void adopt(FreshScene&& fresh);
  // Throws Error naming `call` when `geometry` is not a geometry id.
  void check_geometry(const char* call, std::uint32_t geometry) const;

  Device device_;
  std::string accel_;
  AccelConfig config_;
  mutable std::mutex mutex_;               // the members below
  mutable std::shared_mutex commit_mutex_;  // scene_'s commits (unique) against queries (shared)
  std::vector<GeometryEntry> geometries_;
  std::vector<PlacementEntry> placements_;
  std::vector<std::uint32_t> instance_placement_;  // by instance id
  std::unique_ptr<Scene> scene_;                   // null while flat
  std::atomic<std::size_t> geometry_count_{0}, instance_count_{0};
  std::atomic<bool> instanced_{false};
  mutable std::shared_ptr<const BuiltScene> built_;  // null after a change
};

}  // namespace rtcl::python
