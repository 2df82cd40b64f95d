// Refit of the 8-wide BVH (Accel::refit of "bvh", "bvh-ploc", "bvh-packet";
// kernels/accel/refit.cl): the tree keeps its shape; the triangle blocks are
// filled again from new vertices and every node's child boxes recomputed
// bottom-up, on the device, in the structure's own buffers.
//
// On the device rather than on host threads, because it moves the least
// data: a host refit would write every block and node (about 45 bytes per
// triangle) and upload them; the device receives the vertices only (12
// bytes each: about 6 per triangle of a typical mesh, whose vertices are
// shared by about six triangles, 36 for a soup) and gathers them through a
// table of each block lane's corner indices that it makes from the
// triangles once (kept while the triangles stay the same: the host keeps a
// copy to compare). On a GPU the gather runs at the device's memory
// bandwidth, one lane per work-item with coalesced writes; on a CPU device
// it runs on the same cores a host pool would, with every lane's loads
// independent of the others'.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/accel/bvh.hpp"

namespace rtcl {

// The SAH cost of a wide tree as RefitStats defines it, from its host nodes
// (nodes[0] the root).
double bvh8_cost(std::span<const Bvh8Node> nodes);

// A wide node's weight in that cost, against one block test.
inline constexpr float kRefitNodeCost = 0.5f;

// What a refit needs of one built BVH: its shape (taken from the host image
// at the build), the build's counts, spheres and zero-area triangles, and,
// from the first refit on, its device inputs and kernels.
class Bvh8Refit {
 public:
  Bvh8Refit(const Bvh8& bvh, const Geometry& geometry);
  Bvh8Refit(Bvh8Refit&&) noexcept;
  ~Bvh8Refit();

  double build_cost() const { return build_cost_; }

  // Accel::refit of `accel`, whose nodes and triangle blocks are `nodes`
  // and `triangle_blocks` (see Accel::refit for the checks and errors).
  // Call with the structure's lock held. Sets *bounds to the new root box
  // (the stored primitives' box) when it changes the structure.
  RefitStats run(const Accel& accel, const cl::Buffer& nodes, const cl::Buffer& triangle_blocks,
                 const Geometry& geometry, const RefitPolicy& policy, Aabb* bounds);

 private:
  struct DeviceState;
  // Throws Error for a count, sphere or vertex that a refit cannot take.
  void check(const std::string& name, const Geometry& geometry) const;
  // Whether geometry's triangles are those the lane table was made from.
  bool same_triangles(const Geometry& geometry) const;
  // Throws Error for an index beyond the vertices.
  void check_indices(const std::string& name, const Geometry& geometry) const;
  DeviceState& device_state(const Device& device);

  std::size_t vertex_count_ = 0, triangle_count_ = 0, node_count_ = 0;
  std::size_t lane_count_ = 0;                  // triangle blocks * 8
  std::vector<Sphere> spheres_;                 // as built: a refit moves triangles only
  std::vector<std::uint32_t> zero_area_;        // triangles skipped at the build
  // Node indices by wide depth, deepest level first; level l is
  // order_[level_begin_[l] .. level_begin_[l + 1]) (order_ moves to the
  // device at the first refit).
  std::vector<std::uint32_t> order_, level_begin_;
  double build_cost_ = 0.0, cost_ = 0.0;        // cost_: the tree's now
  std::unique_ptr<DeviceState> device_;
};

}  // namespace rtcl
