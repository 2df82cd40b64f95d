// The meshes of one rtcl.RaycastingScene and the structure built over them.
// Each add_triangles call adds a mesh (a geometry id, in call order); the
// meshes are merged into one Geometry, mesh after mesh, and the structure is
// built at the first query after a change. A hit's primitive in the merged
// geometry maps back to (geometry id, triangle of that mesh) through the
// table of each mesh's first primitive.
//
// Instances (add_instance, set_transform, update_vertices) join here: this
// class owns everything the Python object holds, and queries reach the
// structure only through snapshot().
#pragma once

#include <atomic>
#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/device.hpp"
#include "rtcl/geometry.hpp"

namespace rtcl::python {

// Open3D's invalid id (RaycastingScene.INVALID_ID): geometry and primitive
// ids of a miss.
inline constexpr std::uint32_t kInvalidId = 0xffffffffu;

// What queries run on: immutable once built, shared by the calls in flight.
struct BuiltScene {
  Geometry geometry;                      // every mesh, in geometry id order
  std::vector<std::uint32_t> first_prim;  // mesh g: prims [first_prim[g], first_prim[g + 1])
  std::vector<glm::vec3> normals;         // unit face normal of each triangle, (v1 - v0) x (v2 - v0)
  std::unique_ptr<Accel> accel;           // null when nothing can be hit (no mesh, or only zero-area triangles)

  // The mesh and its triangle of merged primitive `prim` (>= 0).
  void locate(std::int32_t prim, std::uint32_t& geometry_id, std::uint32_t& primitive_id) const;
};

class MeshScene {
 public:
  // `accel` is a structure spec (make_accel); it and config.precision are
  // checked here (Error naming them), the structure itself is built later.
  MeshScene(Device device, std::string accel, AccelConfig config);

  // Adds a mesh: xyz holds 3 floats per vertex, indices 3 per triangle.
  // Throws Error naming add_triangles and the element for a NaN or infinite
  // coordinate or an index out of range; the scene is then unchanged.
  // Returns the mesh's geometry id.
  std::uint32_t add_triangles(std::vector<glm::vec3> vertices, std::vector<glm::uvec3> triangles);

  // The structure over the meshes as they are now, built here when they
  // changed since the last call (one build at a time; concurrent callers
  // wait for it). Thread-safe.
  std::shared_ptr<const BuiltScene> snapshot() const;

  // The meshes added so far (never waits for a build in progress).
  std::size_t geometry_count() const { return geometry_count_.load(); }
  const Device& device() const { return device_; }
  const std::string& accel_spec() const { return accel_; }
  const AccelConfig& config() const { return config_; }

 private:
  struct Mesh {
    std::vector<glm::vec3> vertices;
    std::vector<glm::uvec3> triangles;
  };
  Device device_;
  std::string accel_;
  AccelConfig config_;
  mutable std::mutex mutex_;
  std::vector<std::shared_ptr<const Mesh>> meshes_;
  std::atomic<std::size_t> geometry_count_{0};
  mutable std::shared_ptr<const BuiltScene> built_;  // null after a change
};

}  // namespace rtcl::python
