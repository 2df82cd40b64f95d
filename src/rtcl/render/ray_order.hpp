// Ray orders for coherent packets. A trace kernel that takes 8 consecutive
// rays per work-item (accel "bvh-packet", kernels/accel/bvh_packet.cl) is
// only as fast as those 8 rays are alike; these orders make them alike:
//  - primary rays: screen-tile order (8x8 tiles; each consecutive group of
//    8 rays is one row of one tile), the order the renderer's camera-ray
//    kernel (kernels/render/generate.cl) already uses on the device;
//  - secondary rays: Morton order of (origin, direction), a 60-bit key: the
//    Morton code of the origin quantised within the scene bounds (30 bits,
//    high), then that of the unit direction quantised on [-1, 1] (30 bits,
//    low); 10 bits per axis (after Garanzha and Loop 2010, "Fast ray sorting
//    and breadth-first packet traversal for GPU ray tracing", which sort by a
//    hash of origin and direction). Origin-major because it traces faster
//    than interleaving all six axes, with packets and single rays alike
//    (bench trace/*/diffuse-morton; docs/benchmarks.md).
// An order is a permutation: order[k] is the index (in the original
// sequence) of the ray placed at position k. gather() applies it to rays
// (or anything parallel to them), scatter() puts answers traced in that
// order back into the original order.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "rtcl/aabb.hpp"
#include "rtcl/layouts.hpp"

namespace rtcl {

// Pixel indices (y * width + x) of a width x height image in screen-tile
// order (rtcl_tile_order_pixel): a permutation of 0 .. width*height - 1.
std::vector<std::uint32_t> tile_order(std::uint32_t width, std::uint32_t height);

// Pixel indices (y * width + x) in packet-tile order: 8x8 tiles (rows of
// tiles), each as eight 4x2-pixel packets (rows of packets), each packet
// row by row; clipped at the image's edges. Eight consecutive rays are
// then a 4x2 block, the most compact 8-pixel shape: the order of `rtcl
// bench`'s primary rays, so that the packets it compares with Embree's
// rtcIntersect8 are the ones Embree traces fastest (faster than rows of
// 8x1 pixels; rtcl's packets trace both shapes alike).
std::vector<std::uint32_t> packet_tile_order(std::uint32_t width, std::uint32_t height);

// The 60-bit Morton key of one ray (see above). Origins outside `bounds`
// clamp to its faces; NaN components quantise to 0; a zero direction keys
// as the direction (0, 0, 0).
std::uint64_t ray_morton_key(const Ray& ray, const Aabb& bounds);

// The stable order of rays by ray_morton_key (equal keys keep their
// original order). bounds: the scene's (Geometry::bounds()).
std::vector<std::uint32_t> morton_order(std::span<const Ray> rays, const Aabb& bounds);

// out[k] = items[order[k]]. Throws Error when an index is out of range.
template <class T>
std::vector<T> gather(std::span<const T> items, std::span<const std::uint32_t> order);

// out[order[k]] = items[k]: the inverse of gather for a permutation. Throws
// Error when the sizes differ or an index is out of range.
template <class T>
std::vector<T> scatter(std::span<const T> items, std::span<const std::uint32_t> order);

extern template std::vector<Ray> gather(std::span<const Ray>, std::span<const std::uint32_t>);
extern template std::vector<Hit> gather(std::span<const Hit>, std::span<const std::uint32_t>);
extern template std::vector<Ray> scatter(std::span<const Ray>, std::span<const std::uint32_t>);
extern template std::vector<Hit> scatter(std::span<const Hit>, std::span<const std::uint32_t>);

}  // namespace rtcl
