// Selective ray tracing with interpolation (the lecture's 其他技术: trace
// chosen pixels, e.g. block corners, interpolate the others). The image is
// cut into blocks of `block` pixels whose corners (shared between blocks)
// are traced; a block whose corners differ by at least `threshold` in colour,
// by more than `depth_threshold` in relative depth, or in object (the hit's
// material, or a miss) is cut into four (two when one side is one pixel
// long) at its midlines and the new corners traced; the others are
// interpolated (sparse_image.hpp). All blocks of one subdivision level are
// traced in one batch of the device renderer, so a block of 8 takes at most
// four batches (8 -> 4 -> 2 -> 1).
#pragma once

#include <cstdint>

#include "rtcl/render/renderer.hpp"
#include "rtcl/render/sparse_image.hpp"

namespace rtcl {

struct SelectiveSettings {
  // Side of the first blocks, pixels (1 .. 256; 1 traces every pixel).
  // Speed/accuracy knob: larger blocks trace fewer corners but miss objects
  // smaller than a block that touch none of its corners.
  std::uint32_t block = 8;
  // A block is interpolated only when, per channel, its corners' display
  // values (linear, clamped to [0, 1]) span less than this (>= 0; 0 traces
  // every pixel). Speed/accuracy knob.
  float threshold = 0.05f;
  // ... and its corners' first-hit distances span at most this fraction of
  // the nearest one (>= 0), or all miss.
  float depth_threshold = 0.1f;
};

// What a selective or wavelet-guided render traced.
struct SelectiveStats {
  std::uint64_t traced_pixels = 0;  // of width * height
  std::uint32_t launches = 0;       // batches of the tracer (subdivision levels)
  RayCounts rays;                   // over all batches (with the Renderer)
  double render_ms = 0.0;           // wall clock, tracing and interpolation
};

// Throws Error naming the setting ("selective block", "selective
// threshold", "selective depth threshold") when it is out of range.
void check_selective(const SelectiveSettings& s);

// The selectively traced image of `width` x `height` pixels.
Image render_selective(const PixelTracer& tracer, std::uint32_t width, std::uint32_t height,
                       const SelectiveSettings& s, SelectiveStats* stats = nullptr);

// The tracer of `renderer` for these settings (Renderer::render_pixels),
// adding each batch's rays to stats->rays when given.
PixelTracer renderer_tracer(Renderer& renderer, const RenderSettings& settings, SelectiveStats* stats);

// render_selective with the device renderer.
Image render_selective(Renderer& renderer, const RenderSettings& settings, const SelectiveSettings& s,
                       SelectiveStats* stats = nullptr);

}  // namespace rtcl
