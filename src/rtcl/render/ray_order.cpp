#include "rtcl/render/ray_order.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "rtcl/error.hpp"
#include "rtcl/render/render_layouts.hpp"

namespace rtcl {

namespace {

constexpr int kBitsPerAxis = 10;
constexpr std::uint32_t kCells = 1u << kBitsPerAxis;

// x in [lo, hi] -> 0 .. kCells - 1 (clamped; NaN and an empty range -> 0).
std::uint32_t quantise(float x, float lo, float hi) {
  float f = hi > lo ? (x - lo) / (hi - lo) : 0.0f;
  if (!(f > 0.0f)) return 0;
  if (f >= 1.0f) return kCells - 1;
  return std::min(kCells - 1, static_cast<std::uint32_t>(f * static_cast<float>(kCells)));
}

void check_index(std::uint32_t index, std::size_t size, const char* what) {
  if (index >= size)
    throw Error(std::string(what) + ": order index " + std::to_string(index) + " out of range for " +
                std::to_string(size) + " items");
}

}  // namespace

std::vector<std::uint32_t> tile_order(std::uint32_t width, std::uint32_t height) {
  std::size_t count = static_cast<std::size_t>(width) * height;
  if (count > 0xffffffffu) throw Error("tile_order: " + std::to_string(width) + "x" + std::to_string(height) +
                                       " image has more than 2^32-1 pixels");
  std::vector<std::uint32_t> order(count);
  for (std::size_t i = 0; i < count; ++i)
    order[i] = rtcl_tile_order_pixel(static_cast<std::uint32_t>(i), width, height);
  return order;
}

std::vector<std::uint32_t> packet_tile_order(std::uint32_t width, std::uint32_t height) {
  constexpr std::uint32_t kTile = 8, kPacketWidth = 4, kPacketHeight = 2;
  std::size_t count = static_cast<std::size_t>(width) * height;
  if (count > 0xffffffffu)
    throw Error("packet_tile_order: " + std::to_string(width) + "x" + std::to_string(height) +
                " image has more than 2^32-1 pixels");
  std::vector<std::uint32_t> order;
  order.reserve(count);
  for (std::uint32_t ty = 0; ty < height; ty += kTile)
    for (std::uint32_t tx = 0; tx < width; tx += kTile)
      for (std::uint32_t py = ty; py < std::min(ty + kTile, height); py += kPacketHeight)
        for (std::uint32_t px = tx; px < std::min(tx + kTile, width); px += kPacketWidth)
          for (std::uint32_t y = py; y < std::min(py + kPacketHeight, height); ++y)
            for (std::uint32_t x = px; x < std::min(px + kPacketWidth, width); ++x) order.push_back(y * width + x);
  return order;
}

std::uint64_t ray_morton_key(const Ray& ray, const Aabb& bounds) {
  float length = std::sqrt(ray.dx * ray.dx + ray.dy * ray.dy + ray.dz * ray.dz);
  float inv = length > 0.0f ? 1.0f / length : 0.0f;
  // origin x, y, z, then direction x, y, z
  std::uint32_t q[6] = {quantise(ray.ox, bounds.lower.x, bounds.upper.x),
                        quantise(ray.oy, bounds.lower.y, bounds.upper.y),
                        quantise(ray.oz, bounds.lower.z, bounds.upper.z),
                        quantise(ray.dx * inv, -1.0f, 1.0f),
                        quantise(ray.dy * inv, -1.0f, 1.0f),
                        quantise(ray.dz * inv, -1.0f, 1.0f)};
  std::uint64_t key = 0;
  for (int bit = kBitsPerAxis - 1; bit >= 0; --bit)
    for (int a = 0; a < 3; ++a) key = key << 1 | ((q[a] >> bit) & 1u);
  for (int bit = kBitsPerAxis - 1; bit >= 0; --bit)
    for (int a = 3; a < 6; ++a) key = key << 1 | ((q[a] >> bit) & 1u);
  return key;
}

std::vector<std::uint32_t> morton_order(std::span<const Ray> rays, const Aabb& bounds) {
  if (rays.size() > 0xffffffffu) throw Error("morton_order: more than 2^32-1 rays");
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i)
    keyed[i] = {ray_morton_key(rays[i], bounds), static_cast<std::uint32_t>(i)};
  std::sort(keyed.begin(), keyed.end());  // (key, index): stable by construction
  std::vector<std::uint32_t> order(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) order[i] = keyed[i].second;
  return order;
}

template <class T>
std::vector<T> gather(std::span<const T> items, std::span<const std::uint32_t> order) {
  std::vector<T> out(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    check_index(order[k], items.size(), "gather");
    out[k] = items[order[k]];
  }
  return out;
}

template <class T>
std::vector<T> scatter(std::span<const T> items, std::span<const std::uint32_t> order) {
  if (items.size() != order.size())
    throw Error("scatter: " + std::to_string(items.size()) + " items for an order of " +
                std::to_string(order.size()));
  std::vector<T> out(items.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    check_index(order[k], items.size(), "scatter");
    out[order[k]] = items[k];
  }
  return out;
}

template std::vector<Ray> gather(std::span<const Ray>, std::span<const std::uint32_t>);
template std::vector<Hit> gather(std::span<const Hit>, std::span<const std::uint32_t>);
template std::vector<Ray> scatter(std::span<const Ray>, std::span<const std::uint32_t>);
template std::vector<Hit> scatter(std::span<const Hit>, std::span<const std::uint32_t>);

}  // namespace rtcl
