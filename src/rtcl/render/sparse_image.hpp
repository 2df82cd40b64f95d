// An image of which only some pixels are traced, the rest interpolated:
// the common ground of selective tracing and its wavelet-guided variant
// (selective.hpp; the lecture's 其他技术: trace chosen pixels, interpolate
// the others). Blocks are rectangles of pixels whose four corner pixels are
// traced; neighbouring blocks share their corners and edges.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "rtcl/render/image.hpp"
#include "rtcl/render/renderer.hpp"

namespace rtcl {

// Traces a list of distinct pixels (y * width + x) in one batch and returns
// their samples, parallel to the list (Renderer::render_pixels, or a
// synthetic image in the tests).
using PixelTracer = std::function<PixelSamples(const std::vector<std::uint32_t>& pixels)>;

// Pixels x0 .. x1, y0 .. y1 (inclusive): corners (x0, y0), (x1, y0),
// (x0, y1), (x1, y1).
struct Block {
  std::uint32_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

struct SparseImage {
  std::uint32_t width = 0, height = 0;
  std::vector<float> rgb;            // 3 per pixel, linear; traced or interpolated
  std::vector<float> depth;          // traced pixels only (PixelSamples::depth)
  std::vector<std::int32_t> object;  // traced pixels only (PixelSamples::object)
  std::vector<std::uint8_t> traced;  // 1: traced
  std::uint64_t traced_count = 0;
  std::uint32_t launches = 0;  // calls of the tracer

  SparseImage(std::uint32_t w, std::uint32_t h);
  std::size_t index(std::uint32_t x, std::uint32_t y) const { return std::size_t(y) * width + x; }
  // Traces the pixels of the list not traced yet (duplicates once), in one
  // call of the tracer (none when all are traced).
  void trace(const PixelTracer& tracer, const std::vector<std::uint32_t>& pixels);
  Image image() const;
};

// The blocks of a grid of side `block` over the image: corners at
// x = 0, block, 2 block, ... and the last column (and so for rows), so the
// last blocks are narrower. block >= 1.
std::vector<Block> block_grid(std::uint32_t width, std::uint32_t height, std::uint32_t block);

// The four corner pixels of a block (repeated when it is one pixel wide or
// high), appended to `out`.
void append_corners(const SparseImage& image, const Block& b, std::vector<std::uint32_t>& out);

// b cut at its midlines, appended to `out`: four blocks, or two when one
// side spans fewer than three pixels (b spans at least three in the other).
void split(const Block& b, std::vector<Block>& out);

// Every pixel of the block, appended to `out`.
void append_pixels(const SparseImage& image, const Block& b, std::vector<std::uint32_t>& out);

// Fills the untraced pixels of a block whose corners are traced: a pixel on
// the block's border linearly between the nearest traced pixels of that
// border line (so a neighbour's extra samples on a shared edge are used and
// both blocks give the shared edge the same values: no cracks); an inner
// pixel bilinearly from the four corners. Exact for colours that are affine
// in x and y, up to float rounding.
void interpolate_block(SparseImage& image, const Block& b);

}  // namespace rtcl
