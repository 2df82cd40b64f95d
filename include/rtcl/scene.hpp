// Public API: a scene of meshes and instances (docs/scenes-and-instances.md).
// A mesh is a Geometry built once into a bottom-level structure; an
// instance places a mesh in the world with a 3x4 affine transform (two, for
// motion over the shutter) and a user id that hits report. Queries see the
// instances, never a mesh on its own. commit() builds what changed since
// the last commit and makes it what queries see.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/accel_options.hpp"
#include "rtcl/device.hpp"
#include "rtcl/geometry.hpp"
#include "rtcl/precision.hpp"
#include "rtcl/queries.hpp"

namespace rtcl {

// An affine object-to-world map x -> A x + t, as 3 rows of 4 floats:
// world = (m[r][0] x + m[r][1] y + m[r][2] z + m[r][3]) for row r (the row
// layout of Embree's RTC_FORMAT_FLOAT3X4_ROW_MAJOR). Mirroring (det A < 0)
// and non-uniform scale are allowed; a singular A is not (Scene checks).
struct Transform {
  std::array<std::array<float, 4>, 3> m{{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};

  static Transform identity() { return {}; }
  static Transform translate(float x, float y, float z);
  static Transform scale(float s) { return scale(s, s, s); }
  static Transform scale(float x, float y, float z);
  // A rotation by `degrees` about the axis (x, y, z) (any non-zero length),
  // counter-clockwise looking down the axis (right-handed).
  static Transform rotate(float degrees, float x, float y, float z);
  // From 12 floats, row after row.
  static Transform from_rows(std::span<const float, 12> rows);

  // The composition: (a * b) applies b first, then a. In double, rounded.
  Transform operator*(const Transform& b) const;
  bool operator==(const Transform&) const = default;
};

// Handles, valid in the Scene that returned them until removed; never
// reused by that Scene.
struct MeshId {
  std::uint32_t value = 0;
  bool operator==(const MeshId&) const = default;
};
struct InstanceId {
  std::uint32_t value = 0;
  bool operator==(const InstanceId&) const = default;
};

// What instance_ids outputs hold for a ray that hits nothing.
inline constexpr std::uint32_t kNoInstance = 0xffffffffu;

// One instance of a mesh.
struct Instance {
  MeshId mesh;
  // Object to world; for a moving instance, at time 0 (shutter open).
  Transform transform;
  // A moving instance's object-to-world transform at time 1 (shutter
  // close). At time t in [0, 1] its transform is the element-wise blend
  // (1 - t) * transform + t * at_close, so every point of the mesh moves on
  // a straight line (a large rotation shrinks the mesh in between; a blend
  // that becomes singular is refused). None: static.
  std::optional<Transform> at_close;
  // What instance_ids report for a hit on this instance; none: the
  // InstanceId's value. Not kNoInstance.
  std::optional<std::uint32_t> user_id;
};

// How a mesh is built: a structure of the BVH family as its bottom level
// ("bvh", "bvh-ploc", "bvh-packet", with options: "bvh:bin_count=16").
// Other structures are refused (they have no traversal from an instance).
struct MeshOptions {
  std::string structure = "bvh";
  AccelOptions options;  // applied after the spec's, as AccelConfig::options
  // What the commit after update_vertices does: refits the mesh's tree
  // under this policy (rtcl/accel.hpp; Accel::refit's rules: rebuilt
  // instead when a triangle skipped at the build for zero area has an area
  // now, or when the refitted tree's SAH cost passes max_cost_ratio times
  // the cost at its last build). None: rebuilds it at every update.
  std::optional<RefitPolicy> refit = RefitPolicy{};
};

// What one commit() did.
struct CommitStats {
  std::size_t bottom_levels_built = 0;     // meshes built (new) or rebuilt (vertices updated)
  std::size_t bottom_levels_refitted = 0;  // meshes whose vertices moved and whose trees were refitted
  bool top_level_built = false;            // instances added, removed or changed, or a bottom level
  double build_ms = 0.0;                   // host builds, refits and uploads of this commit
};

struct SceneStats {
  std::size_t meshes = 0;                 // committed
  std::size_t instances = 0;              // committed
  std::size_t bottom_levels_built = 0;    // over every commit so far
  std::size_t bottom_levels_refitted = 0; // over every commit so far
  std::size_t top_levels_built = 0;       // over every commit so far
  std::size_t device_bytes = 0;           // bottom levels, instances and top level on the device
  bool single_level = false;              // the committed scene is one static identity instance
};

struct SceneConfig {
  // The level every query of the scene runs at (rtcl/precision.hpp;
  // docs/scenes-and-instances.md says what each guarantees through
  // instances).
  Precision precision = Precision::robust;
  ScatteredSort scattered_sort = ScatteredSort::measured;  // for the single-level path
};

// Optional per-call arrays of Scene::trace on OpenCL buffers.
struct SceneBuffers {
  // Out: one cl_uint per ray, the hit instance's user id (kNoInstance for a
  // miss). Null: not written.
  cl::Buffer instance_ids;
  // In: ray i's time (a fraction of the shutter, clamped to [0, 1], NaN: 0)
  // is the float at index i * time_stride + time_offset. Null: time 0.
  cl::Buffer times;
  std::uint32_t time_stride = 1, time_offset = 0;
};

class Scene {
 public:
  explicit Scene(const Device& device, const SceneConfig& config = {});
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  // ---- Edits (seen by queries after the next commit) ---------------------
  // Every edit is checked when called and throws Error naming the call, the
  // mesh or instance and the problem; a call that throws changes nothing.

  // Adds a mesh (copied; validated as make_accel validates geometry). Not
  // visible until an instance places it.
  MeshId add_mesh(const Geometry& geometry, const MeshOptions& options = {});
  // New vertex positions for the mesh's triangles (3 floats per vertex, the
  // mesh's vertex count); the triangles and spheres stay. The next commit
  // refits its bottom level (the same tree, new boxes), or rebuilds it where
  // the mesh's MeshOptions::refit says so (CommitStats counts either).
  void update_vertices(MeshId mesh, std::span<const float> xyz);
  // Removes a mesh that no instance uses (an Error names the instances that
  // still do).
  void remove_mesh(MeshId mesh);

  InstanceId add_instance(const Instance& instance);
  InstanceId add_instance(MeshId mesh, const Transform& transform = Transform::identity()) {
    return add_instance(Instance{mesh, transform, std::nullopt, std::nullopt});
  }
  // Replaces an instance's mesh, transforms and user id.
  void set_instance(InstanceId id, const Instance& instance);
  // A new static transform (a moving instance stops moving); mesh and user
  // id stay.
  void set_transform(InstanceId id, const Transform& transform);
  void remove_instance(InstanceId id);
  // The instance as last set (pending edits included).
  Instance instance(InstanceId id) const;

  // Builds the bottom levels of meshes added since the last commit, refits
  // or rebuilds those updated and, when instances were added, removed or
  // changed or a bottom level changed, the top level (a BVH over the
  // instances' world boxes), uploads them and makes them what queries see.
  // On an exception the scene stays as it was: the previous commit answers
  // queries and the edits stay pending.
  CommitStats commit();

  // ---- Queries (of the last commit) ---------------------------------------
  // Thread-safe: any number of threads may query and one may commit at
  // once; a query runs on the commit that was the latest when it started
  // (a commit in progress never blocks queries, nor they it). Queries of
  // one scene run one after another (its lock, as an Accel's). Before the
  // first commit every ray misses.
  //
  // hits[i]: the closest (Query::closest) or some (Query::any) hit of ray
  // i, prim being the primitive within its mesh (triangles, then spheres,
  // as in Geometry); t in units of the world ray's direction.
  // instance_ids (empty, or one per ray): the hit instance's user id, else
  // kNoInstance. times (empty, or one per ray): each ray's time for moving
  // instances (fractions of the shutter, clamped to [0, 1], NaN: 0); empty:
  // time 0. Sizes are checked before anything is written. `coherence` is
  // Accel's promise, for the single-level path; two levels trace one ray
  // per work-item whatever it says.
  void trace(Query query, const Rays& rays, std::span<Hit> hits, std::span<std::uint32_t> instance_ids = {},
             std::span<const float> times = {}, Coherence coherence = Coherence::incoherent) const;
  std::vector<Hit> intersect(const Rays& rays, std::span<std::uint32_t> instance_ids = {},
                             std::span<const float> times = {}) const;
  std::vector<std::uint8_t> occluded(const Rays& rays, std::span<const float> times = {}) const;
  // The same on the caller's buffers (Accel::trace's contract): enqueued
  // after `wait`, returns the event that ends it.
  cl::Event trace(Query query, const cl::Buffer& rays, const cl::Buffer& hits, std::size_t ray_count,
                  const SceneBuffers& extra = {}, const std::vector<cl::Event>& wait = {},
                  Coherence coherence = Coherence::incoherent) const;

  SceneStats stats() const;
  const Device& device() const;
  Precision precision() const;

  struct State;  // internal (src/rtcl/scene/scene.cpp)

 private:
  std::unique_ptr<State> state_;
};

}  // namespace rtcl
