// The image split into square tiles for rendering in pieces (rtcl render
// under mpirun hands them out one at a time). Tiles are aligned to the
// renderer's 8x8 ray-order tiles (RTCL_TILE), so each is rendered from the
// same camera-ray packets as the whole image (Renderer::render with a
// region).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "rtcl/render/renderer.hpp"

namespace rtcl {

// rows: left to right, top to bottom; shuffled: a fixed pseudo-random
// permutation of that (the same on every machine), to check that the order
// changes nothing and to spread costly regions over the run.
enum class TileOrder { rows, shuffled };

// "rows" | "shuffled"; throws Error naming the text otherwise.
TileOrder parse_tile_order(std::string_view text);

// The tiles of a width x height image, `tile` pixels square (the last
// column and row narrower where the image is not a multiple), in `order`.
// They cover every pixel exactly once. Throws Error when tile is not a
// positive multiple of 8 or the image is empty.
std::vector<ImageRegion> image_tiles(std::uint32_t width, std::uint32_t height, std::uint32_t tile, TileOrder order);

// Copies `part` (an image of region's size) into `image` at the region.
void paste(Image& image, const ImageRegion& region, const Image& part);

}  // namespace rtcl
