// The device side of a committed two-level scene (internal; rtcl/scene.hpp
// is the API): the meshes' bottom levels (8-wide BVHs in the BVH
// structure's layout) concatenated in one set of buffers, the instance
// records, and a top-level 8-wide BVH over the instances' world boxes,
// traced by kernels/accel/instances.cl. The layouts: BottomLevel,
// InstanceRecord and InstanceMotion (kernels/shared/layouts.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/accel/bvh.hpp"
#include "rtcl/layouts.hpp"
#include "rtcl/scene.hpp"

namespace rtcl {

// A mesh's bottom level as built on the host: the BVH image the
// concatenation copies, and what make_bvh_accel needs for the single-level
// path. Immutable once built; shared by the commits that use it.
struct MeshBuild {
  std::shared_ptr<const Geometry> geometry;
  std::string structure;  // "bvh", "bvh-ploc" or "bvh-packet"
  BvhConfig config;
  BuiltBvh built;
  // The boxes of the root node's children (object space): an instance's
  // world box is the box of their transformed corners.
  std::vector<Aabb> root_boxes;
  // The tree's SAH cost (bvh8_cost) at its build; a refit keeps it.
  double build_cost = 0.0;
};

// The bottom levels of a commit on the device, in the order given.
struct DeviceBottoms {
  cl::Buffer levels, nodes, triangles, spheres;
  std::uint32_t stack_size = 0;  // the largest of the meshes' (Bvh8::stack_size)
  bool spheres_present = false;
  std::size_t bytes = 0;
};
DeviceBottoms upload_bottoms(const Device& device, std::span<const std::shared_ptr<const MeshBuild>> meshes);

// An instance as the top level takes it: its bottom level (index into the
// uploaded meshes), transforms and user id, checked by the Scene.
struct PlacedInstance {
  std::uint32_t bottom = 0;
  Transform transform;
  std::optional<Transform> at_close;
  std::uint32_t user_id = 0;
};

// A transform's linear part and translation in double.
glm::dmat3 linear_part(const Transform& t);
glm::dvec3 translation_part(const Transform& t);

// "" when the transform can place an instance, else what is wrong with it:
// a NaN or infinite element, or a singular linear part (its determinant is
// zero or below 2^-20 of the product of its rows' lengths, or its inverse
// is not finite in float).
std::string transform_problem(const Transform& transform);
// The same for a moving instance's two transforms and their blend over
// [0, 1].
std::string motion_problem(const Transform& open, const Transform& close);

// A mesh's root boxes (MeshBuild::root_boxes) in eight float lanes per
// bound, lanes beyond them copies of the first: the form the pass over the
// instances transforms.
struct RootBoxes {
  float lower[3][RTCL_BLOCK_WIDTH];
  float upper[3][RTCL_BLOCK_WIDTH];
};
RootBoxes root_boxes_of(const MeshBuild& mesh);

// The world box of a mesh (its root boxes) placed by the instance: a box
// holding its root boxes' corners under the transform (both transforms of
// a moving one: every point moves on a straight line between them),
// computed in float with a margin for its rounding, and widened by
// kInstanceBoxWiden of its coordinates' magnitude for the rounding of the
// object-space ray (docs/scenes-and-instances.md, "Precision").
inline constexpr double kInstanceBoxWiden = 64.0 * 5.9604644775390625e-8;  // 64 float ulps (2^-24 each)
Aabb instance_world_box(const RootBoxes& roots, const Transform& transform, const std::optional<Transform>& at_close);

// The top level over instances: the 8-wide tree (child references: inner
// node >= 0, instance k as ~k, RTCL_CHILD_EMPTY) and its stack bound, the
// nodes[0] root always present (all slots empty for no instance).
struct TopLevel {
  std::vector<Bvh8Node> nodes;
  std::uint32_t stack_size = 0;
};
TopLevel build_top_level(std::span<const Aabb> world_boxes);
// The same into `top`, whose arrays' room is reused.
void build_top_level(std::span<const Aabb> world_boxes, TopLevel& top);

// The host arrays of a top-level build, handed from one commit's TwoLevel
// to the next (a scene's commits run one at a time) so that a commit
// writes into pages it wrote before: on a virtual machine, faulting fresh
// pages in was a quarter of a commit of 100k instances. They hold the last
// build's intermediates (some 130 bytes per instance) and nothing a query
// reads.
struct TopScratch {
  std::vector<std::uint32_t> motion_index;
  std::vector<Aabb> boxes;
  std::vector<InstanceRecord> records;
  std::vector<InstanceMotion> motions;
  TopLevel top;
};

// One commit's two-level structure on the device.
class TwoLevel {
 public:
  // Uploads the instances (records, motions, top level) over `bottoms`
  // (shared with other commits over the same meshes) and builds the
  // closest-hit program, or takes the programs of `previous` (the last
  // commit's, when it has one) where they were built with the same options,
  // and its TopScratch.
  TwoLevel(const Device& device, Precision precision, std::shared_ptr<const DeviceBottoms> bottoms,
           std::span<const std::shared_ptr<const MeshBuild>> meshes, std::span<const PlacedInstance> instances,
           const TwoLevel* previous = nullptr);

  // The query of rays[0 .. ray_count) into hits (and instance ids, when
  // given); ray i's time is times[i * time_stride + time_offset] when
  // `times` is given, else 0. Thread-safe (a lock around the enqueue).
  cl::Event trace(Query query, const cl::Buffer& rays, const cl::Buffer& hits, std::size_t ray_count,
                  const cl::Buffer* instance_ids, const cl::Buffer* times, std::uint32_t time_stride,
                  std::uint32_t time_offset, const std::vector<cl::Event>& wait) const;

  const std::shared_ptr<const DeviceBottoms>& bottoms() const { return bottoms_; }
  std::size_t device_bytes() const { return bytes_ + bottoms_->bytes; }
  bool moving() const { return moving_; }

 private:
  cl::Kernel& kernel(Query query) const;
  static std::vector<std::string> with_query(std::vector<std::string> defines, Query query);

  Device device_;
  std::shared_ptr<const DeviceBottoms> bottoms_;
  std::shared_ptr<TopScratch> scratch_;  // written by constructors alone
  cl::Buffer top_, instances_, motions_, no_times_, no_ids_;
  std::vector<std::string> defines_;
  std::size_t bytes_ = 0;
  bool moving_ = false;
  mutable std::mutex mutex_;
  // Per query (closest, any): the program (Device::program assembles and
  // hashes the source at every call) and its kernel with this commit's
  // arguments, each made at its first use.
  mutable std::optional<cl::Program> programs_[2];
  mutable std::optional<cl::Kernel> kernels_[2];
};

}  // namespace rtcl
