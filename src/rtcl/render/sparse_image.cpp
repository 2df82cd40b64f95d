#include "rtcl/render/sparse_image.hpp"

#include <algorithm>

#include "rtcl/error.hpp"

namespace rtcl {

SparseImage::SparseImage(std::uint32_t w, std::uint32_t h)
    : width(w),
      height(h),
      rgb(std::size_t(w) * h * 3, 0.0f),
      depth(std::size_t(w) * h, 0.0f),
      object(std::size_t(w) * h, -1),
      traced(std::size_t(w) * h, 0) {}

void SparseImage::trace(const PixelTracer& tracer, const std::vector<std::uint32_t>& pixels) {
  std::vector<std::uint32_t> todo;
  todo.reserve(pixels.size());
  for (std::uint32_t p : pixels)
    if (!traced[p]) {
      traced[p] = 2;  // queued in this call
      todo.push_back(p);
    }
  if (todo.empty()) return;
  // Row-major order keeps neighbouring camera rays together.
  std::sort(todo.begin(), todo.end());
  PixelSamples s = tracer(todo);
  if (s.rgb.size() != todo.size() * 3 || s.depth.size() != todo.size() || s.object.size() != todo.size())
    throw Error("selective tracing: the tracer returned " + std::to_string(s.depth.size()) + " samples for " +
                std::to_string(todo.size()) + " pixels");
  for (std::size_t i = 0; i < todo.size(); ++i) {
    const std::uint32_t p = todo[i];
    for (int c = 0; c < 3; ++c) rgb[std::size_t(p) * 3 + c] = s.rgb[i * 3 + c];
    depth[p] = s.depth[i];
    object[p] = s.object[i];
    traced[p] = 1;
  }
  traced_count += todo.size();
  launches++;
}

Image SparseImage::image() const {
  Image out;
  out.width = width;
  out.height = height;
  out.rgb = rgb;
  return out;
}

std::vector<Block> block_grid(std::uint32_t width, std::uint32_t height, std::uint32_t block) {
  auto lines = [block](std::uint32_t n) {
    std::vector<std::uint32_t> at;
    for (std::uint32_t v = 0; v < n; v += block) at.push_back(v);
    if (at.back() != n - 1) at.push_back(n - 1);
    return at;
  };
  const std::vector<std::uint32_t> xs = lines(width), ys = lines(height);
  std::vector<Block> blocks;
  // A one-pixel-wide (or -high) image is one column (row) of blocks of zero width.
  const std::size_t nx = std::max<std::size_t>(xs.size() - 1, 1), ny = std::max<std::size_t>(ys.size() - 1, 1);
  for (std::size_t j = 0; j < ny; ++j)
    for (std::size_t i = 0; i < nx; ++i)
      blocks.push_back(Block{xs[i], ys[j], xs[std::min(i + 1, xs.size() - 1)], ys[std::min(j + 1, ys.size() - 1)]});
  return blocks;
}

void append_corners(const SparseImage& image, const Block& b, std::vector<std::uint32_t>& out) {
  for (std::uint32_t y : {b.y0, b.y1})
    for (std::uint32_t x : {b.x0, b.x1}) out.push_back(static_cast<std::uint32_t>(image.index(x, y)));
}

void append_pixels(const SparseImage& image, const Block& b, std::vector<std::uint32_t>& out) {
  for (std::uint32_t y = b.y0; y <= b.y1; ++y)
    for (std::uint32_t x = b.x0; x <= b.x1; ++x) out.push_back(static_cast<std::uint32_t>(image.index(x, y)));
}

void split(const Block& b, std::vector<Block>& out) {
  const bool cut_x = b.x1 - b.x0 >= 2, cut_y = b.y1 - b.y0 >= 2;
  const std::uint32_t mx = b.x0 + (b.x1 - b.x0) / 2, my = b.y0 + (b.y1 - b.y0) / 2;
  if (cut_x && cut_y) {
    out.push_back({b.x0, b.y0, mx, my});
    out.push_back({mx, b.y0, b.x1, my});
    out.push_back({b.x0, my, mx, b.y1});
    out.push_back({mx, my, b.x1, b.y1});
  } else if (cut_x) {
    out.push_back({b.x0, b.y0, mx, b.y1});
    out.push_back({mx, b.y0, b.x1, b.y1});
  } else {
    out.push_back({b.x0, b.y0, b.x1, my});
    out.push_back({b.x0, my, b.x1, b.y1});
  }
}

namespace {

// Fills the untraced pixels of one border line (n pixels, the i-th at
// index first + i * stride; its two ends traced) linearly between the
// nearest traced pixels.
void interpolate_line(SparseImage& image, std::size_t first, std::size_t stride, std::uint32_t n) {
  std::uint32_t last = 0;  // the last traced position
  for (std::uint32_t i = 1; i < n; ++i) {
    if (!image.traced[first + i * stride]) continue;
    const float* a = &image.rgb[(first + last * stride) * 3];
    const float* b = &image.rgb[(first + i * stride) * 3];
    for (std::uint32_t k = last + 1; k < i; ++k) {
      const float t = float(k - last) / float(i - last);
      float* out = &image.rgb[(first + k * stride) * 3];
      for (int c = 0; c < 3; ++c) out[c] = a[c] + t * (b[c] - a[c]);
    }
    last = i;
  }
}

}  // namespace

void interpolate_block(SparseImage& image, const Block& b) {
  const std::uint32_t w = b.x1 - b.x0 + 1, h = b.y1 - b.y0 + 1;
  interpolate_line(image, image.index(b.x0, b.y0), 1, w);
  interpolate_line(image, image.index(b.x0, b.y1), 1, w);
  interpolate_line(image, image.index(b.x0, b.y0), image.width, h);
  interpolate_line(image, image.index(b.x1, b.y0), image.width, h);
  if (w < 3 || h < 3) return;
  const float* c00 = &image.rgb[image.index(b.x0, b.y0) * 3];
  const float* c10 = &image.rgb[image.index(b.x1, b.y0) * 3];
  const float* c01 = &image.rgb[image.index(b.x0, b.y1) * 3];
  const float* c11 = &image.rgb[image.index(b.x1, b.y1) * 3];
  for (std::uint32_t y = b.y0 + 1; y < b.y1; ++y) {
    const float fy = float(y - b.y0) / float(h - 1);
    for (std::uint32_t x = b.x0 + 1; x < b.x1; ++x) {
      const std::size_t p = image.index(x, y);
      if (image.traced[p]) continue;
      const float fx = float(x - b.x0) / float(w - 1);
      for (int c = 0; c < 3; ++c) {
        const float top = c00[c] + fx * (c10[c] - c00[c]);
        const float bottom = c01[c] + fx * (c11[c] - c01[c]);
        image.rgb[p * 3 + c] = top + fy * (bottom - top);
      }
    }
  }
}

}  // namespace rtcl
