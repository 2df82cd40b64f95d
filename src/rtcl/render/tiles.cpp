#include "rtcl/render/tiles.hpp"

#include <algorithm>
#include <random>

#include "rtcl/error.hpp"
#include "rtcl/render/render_layouts.hpp"

namespace rtcl {

TileOrder parse_tile_order(std::string_view text) {
  if (text == "rows") return TileOrder::rows;
  if (text == "shuffled") return TileOrder::shuffled;
  throw Error("tile order '" + std::string(text) + "': must be rows or shuffled");
}

std::vector<ImageRegion> image_tiles(std::uint32_t width, std::uint32_t height, std::uint32_t tile, TileOrder order) {
  if (tile == 0 || tile % RTCL_TILE != 0 || tile > 65536)
    throw Error("tile size " + std::to_string(tile) + ": must be a multiple of " + std::to_string(RTCL_TILE) +
                " in 8 .. 65536 (tiles follow the renderer's 8x8 ray order)");
  if (width == 0 || height == 0)
    throw Error("image size " + std::to_string(width) + "x" + std::to_string(height) + ": nothing to split");
  std::vector<ImageRegion> tiles;
  for (std::uint32_t y = 0; y < height; y += tile)
    for (std::uint32_t x = 0; x < width; x += tile)
      tiles.push_back({x, y, std::min(tile, width - x), std::min(tile, height - y)});
  if (order == TileOrder::shuffled) {
    // std::shuffle's algorithm is implementation-defined; Fisher-Yates with
    // mt19937's fully specified sequence is the same everywhere.
    std::mt19937 random(20260101u);
    for (std::size_t i = tiles.size(); i > 1; --i) std::swap(tiles[i - 1], tiles[random() % i]);
  }
  return tiles;
}

void paste(Image& image, const ImageRegion& region, const Image& part) {
  if (part.width != region.width || part.height != region.height || region.x0 + region.width > image.width ||
      region.y0 + region.height > image.height)
    throw Error("tile " + std::to_string(part.width) + "x" + std::to_string(part.height) + " does not fit region " +
                std::to_string(region.width) + "x" + std::to_string(region.height) + " at (" +
                std::to_string(region.x0) + ", " + std::to_string(region.y0) + ") of the " +
                std::to_string(image.width) + "x" + std::to_string(image.height) + " image");
  for (std::uint32_t y = 0; y < region.height; ++y)
    std::copy_n(part.rgb.begin() + std::size_t(y) * region.width * 3, std::size_t(region.width) * 3,
                image.rgb.begin() + (std::size_t(region.y0 + y) * image.width + region.x0) * 3);
}

}  // namespace rtcl
