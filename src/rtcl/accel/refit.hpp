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
// copy to compare). One launch does the rest (refit.cl, refit_bottom_up):
// one work-item per node with triangle blocks fills their lanes and carries
// the node's box up the tree, the last child to arrive at a node finishing
// it, so that a small mesh pays one launch, not one per level of the tree;
// on a CPU device it runs on the same cores a host pool would, with every
// block's loads independent of the others'.
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

// The refit of a host image (the scene's bottom levels, src/rtcl/scene/
// mesh_refit.hpp, which keep their images and upload them): the same
// update as the device's, on up to `threads` host threads (0 = all; the
// result does not depend on them). Every used lane of a triangle block is
// filled again from geometry's vertices through its primitive id, and
// every node's child boxes are recomputed bottom-up as the exact float
// minima and maxima of what lies below (sphere lanes stay as built).
// `geometry` must be the one the image was built over with new vertices
// (the caller checks counts and values); nothing checks zero-area
// triangles or the cost (bvh8_cost does).
void refit_bvh8(Bvh8& bvh, const Geometry& geometry, unsigned threads = 0);

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
  // Throws Error for a count or sphere that a refit cannot take.
  void check(const std::string& name, const Geometry& geometry) const;
  // One pass over geometry (after device_state): throws Error for a vertex
  // that is not finite; returns whether geometry's triangles are those the
  // lane table was made from.
  bool scan(const std::string& name, const Geometry& geometry) const;
  // Throws Error for an index beyond the vertices.
  void check_indices(const std::string& name, const Geometry& geometry) const;
  DeviceState& device_state(const Device& device);

  std::size_t vertex_count_ = 0, triangle_count_ = 0, node_count_ = 0;
  std::size_t lane_count_ = 0;                  // triangle blocks * 8
  std::vector<Sphere> spheres_;                 // as built: a refit moves triangles only
  std::vector<std::uint32_t> zero_area_;        // triangles skipped at the build
  // The tree's shape for refit.cl's refit_bottom_up (moved to the device
  // at the first refit): each node's parent * 8 + lane (the root's
  // 0xffffffff), the lanes each node waits for, the nodes with triangle
  // blocks among their lanes, and the nodes that wait for none.
  std::vector<std::uint32_t> up_, arrivals_, block_nodes_, start_nodes_;
  double build_cost_ = 0.0, cost_ = 0.0;        // cost_: the tree's now
  std::unique_ptr<DeviceState> device_;
};

}  // namespace rtcl
