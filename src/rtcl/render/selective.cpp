#include "rtcl/render/selective.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "rtcl/error.hpp"

namespace rtcl {

namespace {

// Whether the traced corners of b agree closely enough to interpolate it.
bool smooth(const SparseImage& image, const Block& b, const SelectiveSettings& s) {
  const std::size_t c[4] = {image.index(b.x0, b.y0), image.index(b.x1, b.y0), image.index(b.x0, b.y1),
                            image.index(b.x1, b.y1)};
  for (int k = 1; k < 4; ++k)
    if (image.object[c[k]] != image.object[c[0]]) return false;
  for (int ch = 0; ch < 3; ++ch) {
    float lo = 1.0f, hi = 0.0f;
    for (std::size_t p : c) {
      const float v = std::clamp(image.rgb[p * 3 + ch], 0.0f, 1.0f);
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    if (!(hi - lo < s.threshold)) return false;
  }
  if (image.object[c[0]] < 0) return true;  // all miss
  float near = INFINITY, far = 0.0f;
  for (std::size_t p : c) {
    near = std::min(near, image.depth[p]);
    far = std::max(far, image.depth[p]);
  }
  return far - near <= s.depth_threshold * near;
}

}  // namespace

void check_selective(const SelectiveSettings& s) {
  if (s.block == 0 || s.block > 256)
    throw Error("selective block " + std::to_string(s.block) + ": must be 1 .. 256 pixels");
  if (!std::isfinite(s.threshold) || s.threshold < 0.0f)
    throw Error("selective threshold " + std::to_string(s.threshold) + ": must be finite and not negative");
  if (!std::isfinite(s.depth_threshold) || s.depth_threshold < 0.0f)
    throw Error("selective depth threshold " + std::to_string(s.depth_threshold) +
                ": must be finite and not negative");
}

Image render_selective(const PixelTracer& tracer, std::uint32_t width, std::uint32_t height,
                       const SelectiveSettings& s, SelectiveStats* stats) {
  check_selective(s);
  auto start = std::chrono::steady_clock::now();
  SparseImage image(width, height);
  std::vector<Block> blocks = block_grid(width, height, s.block), smooth_blocks, next;
  std::vector<std::uint32_t> corners;
  for (const Block& b : blocks) append_corners(image, b, corners);
  image.trace(tracer, corners);
  while (!blocks.empty()) {
    next.clear();
    corners.clear();
    for (const Block& b : blocks) {
      if (b.x1 - b.x0 <= 1 && b.y1 - b.y0 <= 1) continue;  // every pixel is a corner
      if (smooth(image, b, s)) {
        smooth_blocks.push_back(b);
        continue;
      }
      const std::size_t first = next.size();
      split(b, next);
      for (std::size_t i = first; i < next.size(); ++i) append_corners(image, next[i], corners);
    }
    image.trace(tracer, corners);
    std::swap(blocks, next);
  }
  for (const Block& b : smooth_blocks) interpolate_block(image, b);
  if (stats) {
    stats->traced_pixels = image.traced_count;
    stats->launches = image.launches;
    stats->render_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  return image.image();
}

PixelTracer renderer_tracer(Renderer& renderer, const RenderSettings& settings, SelectiveStats* stats) {
  return [&renderer, settings, stats](const std::vector<std::uint32_t>& pixels) {
    PixelSamples samples = renderer.render_pixels(settings, pixels);
    if (stats) {
      const RayCounts& r = renderer.stats().rays;
      stats->rays.camera += r.camera;
      stats->rays.shadow += r.shadow;
      stats->rays.reflection += r.reflection;
      stats->rays.refraction += r.refraction;
    }
    return samples;
  };
}

Image render_selective(Renderer& renderer, const RenderSettings& settings, const SelectiveSettings& s,
                       SelectiveStats* stats) {
  SelectiveStats local;
  SelectiveStats* out = stats ? stats : &local;
  *out = SelectiveStats{};
  return render_selective(renderer_tracer(renderer, settings, out), settings.width, settings.height, s, out);
}

}  // namespace rtcl
