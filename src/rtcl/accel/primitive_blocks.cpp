#include "rtcl/accel/primitive_blocks.hpp"
#include "rtcl/cl/upload_consuming.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rtcl/error.hpp"

namespace rtcl {

TriangleBlock empty_triangle_block() {
  TriangleBlock b;
  for (auto& vertex : b.v)
    for (auto& axis : vertex)
      for (float& lane : axis) lane = std::numeric_limits<float>::quiet_NaN();
  for (int& p : b.prim) p = -1;
  return b;
}

SphereBlock empty_sphere_block() {
  SphereBlock b;
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
    b.cx[lane] = b.cy[lane] = b.cz[lane] = 0.0f;
    b.r[lane] = std::numeric_limits<float>::quiet_NaN();
    b.prim[lane] = -1;
  }
  return b;
}

rtcl_i32 PrimitiveBlocks::append(const Geometry& g, std::span<const std::uint32_t> prims) {
  if (prims.empty() || prims.size() > RTCL_BLOCK_WIDTH) throw Error("internal: leaf of " + std::to_string(prims.size()) + " primitives");
  bool spheres_leaf = prims[0] >= g.triangles.size();
  if (!spheres_leaf) {
    TriangleBlock b = empty_triangle_block();
    for (std::size_t lane = 0; lane < prims.size(); ++lane) {
      if (prims[lane] >= g.triangles.size()) throw Error("internal: mixed leaf");
      const glm::uvec3& t = g.triangles[prims[lane]];
      set_lane(b, lane, prims[lane], g.vertices[t.x], g.vertices[t.y], g.vertices[t.z]);
    }
    triangles.push_back(b);
    return RTCL_LEAF_TRIANGLES(triangles.size() - 1);
  }
  SphereBlock b = empty_sphere_block();
  for (std::size_t lane = 0; lane < prims.size(); ++lane) {
    if (prims[lane] < g.triangles.size()) throw Error("internal: mixed leaf");
    set_lane(b, lane, prims[lane], g.spheres[prims[lane] - g.triangles.size()]);
  }
  spheres.push_back(b);
  return RTCL_LEAF_SPHERES(spheres.size() - 1);
}

std::size_t PrimitiveBlocks::bytes() const {
  return triangles.size() * sizeof(TriangleBlock) + spheres.size() * sizeof(SphereBlock);
}

namespace {

// Each kind's blocks through upload(data, bytes, what); a kind with no
// block gets its one-block placeholder.
template <class Upload>
DevicePrimitives upload_with(const Device& device, const PrimitiveBlocks& blocks, Upload upload) {
  DevicePrimitives out;
  TriangleBlock no_triangle{};
  SphereBlock no_sphere{};
  out.triangles = blocks.triangles.empty()
                      ? device.upload(&no_triangle, sizeof no_triangle, "triangle blocks")
                      : upload(blocks.triangles.data(), blocks.triangles.size() * sizeof(TriangleBlock),
                               "triangle blocks");
  out.spheres = blocks.spheres.empty()
                    ? device.upload(&no_sphere, sizeof no_sphere, "sphere blocks")
                    : upload(blocks.spheres.data(), blocks.spheres.size() * sizeof(SphereBlock), "sphere blocks");
  out.bytes = blocks.bytes();
  return out;
}

}  // namespace

DevicePrimitives upload(const Device& device, const PrimitiveBlocks& blocks) {
  return upload_with(device, blocks, [&](const void* data, std::size_t bytes, const char* what) {
    return device.upload(data, bytes, what);
  });
}

DevicePrimitives upload_consuming(const Device& device, PrimitiveBlocks&& blocks) {
  DevicePrimitives out = upload_with(device, blocks, [&](const void* data, std::size_t bytes, const char* what) {
    return upload_consuming(device, const_cast<void*>(data), bytes, what);
  });
  blocks = PrimitiveBlocks{};
  return out;
}

PrimitiveBlocks in_order_blocks(const Geometry& geometry, const std::vector<std::uint32_t>& ids) {
  PrimitiveBlocks blocks;
  std::size_t first_sphere = ids.size() - geometry.spheres.size();
  for (std::size_t begin = 0; begin < ids.size();) {
    std::size_t kind_end = begin < first_sphere ? first_sphere : ids.size();
    std::size_t end = std::min(begin + RTCL_BLOCK_WIDTH, kind_end);
    blocks.append(geometry, std::span(ids).subspan(begin, end - begin));
    begin = end;
  }
  return blocks;
}

std::vector<std::uint32_t> stored_primitives(const Geometry& g) {
  std::vector<std::uint32_t> ids;
  ids.reserve(g.primitive_count());
  for (std::size_t i = 0; i < g.triangles.size(); ++i)
    if (!zero_area(g, i)) ids.push_back(static_cast<std::uint32_t>(i));
  for (std::size_t i = 0; i < g.spheres.size(); ++i) ids.push_back(static_cast<std::uint32_t>(g.triangles.size() + i));
  return ids;
}

}  // namespace rtcl
