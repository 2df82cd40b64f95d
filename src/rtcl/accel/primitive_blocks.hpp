// Primitive data in leaf order: blocks of up to eight triangles or eight
// spheres in SoA form (kernels/shared/layouts.h), shared by every structure.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "rtcl/device.hpp"
#include "rtcl/default_init_allocator.hpp"
#include "rtcl/layouts.hpp"
#include "rtcl/geometry.hpp"

namespace rtcl {

// A block whose lanes are all unused: NaN vertices (triangles) or NaN radius
// and zero centre (spheres), prim = -1.
TriangleBlock empty_triangle_block();
SphereBlock empty_sphere_block();

// Stores primitive `prim` in `lane` of a block: a triangle's corners a, b, c
// or a sphere.
inline void set_lane(TriangleBlock& block, std::size_t lane, std::uint32_t prim, const glm::vec3& a,
                     const glm::vec3& b, const glm::vec3& c) {
  for (int axis = 0; axis < 3; ++axis) {
    block.v[0][axis][lane] = a[axis];
    block.v[1][axis][lane] = b[axis];
    block.v[2][axis][lane] = c[axis];
  }
  block.prim[lane] = static_cast<rtcl_i32>(prim);
}
inline void set_lane(SphereBlock& block, std::size_t lane, std::uint32_t prim, const Sphere& s) {
  block.cx[lane] = s.center.x;
  block.cy[lane] = s.center.y;
  block.cz[lane] = s.center.z;
  block.r[lane] = s.radius;
  block.prim[lane] = static_cast<rtcl_i32>(prim);
}

// Blocks are trivial: resize() leaves them unwritten for their filler.
struct PrimitiveBlocks {
  std::vector<TriangleBlock, DefaultInitAllocator<TriangleBlock>> triangles;
  std::vector<SphereBlock, DefaultInitAllocator<SphereBlock>> spheres;

  // Appends one block holding `prims` (1..8 ids, all triangles or all spheres
  // of `geometry`) and returns its leaf child reference (RTCL_LEAF_*).
  rtcl_i32 append(const Geometry& geometry, std::span<const std::uint32_t> prims);
  std::size_t bytes() const;
};

// The blocks on the device. A kind with no block gets a one-block placeholder
// buffer so that kernel signatures never change.
struct DevicePrimitives {
  cl::Buffer triangles, spheres;
  std::size_t bytes = 0;
};
DevicePrimitives upload(const Device& device, const PrimitiveBlocks& blocks);
// The same, for blocks the caller gives up: each array's host pages go back
// part by part as they reach the device (cl/upload_consuming.hpp), and
// `blocks` is empty afterwards.
DevicePrimitives upload_consuming(const Device& device, PrimitiveBlocks&& blocks);

// Ids of the primitives a structure stores: every sphere and every triangle
// whose area is not zero.
std::vector<std::uint32_t> stored_primitives(const Geometry& geometry);

// The stored primitives (`ids` = stored_primitives(geometry)) in id order,
// eight to a block: triangle k of `ids` is lane k & 7 of triangle block
// k >> 3, sphere j is lane j & 7 of sphere block j >> 3. What brute force
// walks, and what indexed structures (cells, leaves sharing primitives)
// reference: a reference is that k or j (kernels/shared/triangle.h,
// intersect_triangle_refs).
PrimitiveBlocks in_order_blocks(const Geometry& geometry, const std::vector<std::uint32_t>& ids);

}  // namespace rtcl
