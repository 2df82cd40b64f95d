// Host reference of the Whitted renderer: the same algorithm as
// kernels/render/shade.cl (IntersectColor with Phong, hard and soft shadows,
// Fresnel-weighted reflection and refraction, glossy reflection, thin lens,
// depth limit, weight threshold), the same sample points
// (kernels/shared/sampling.h: sampler, seed, filter, light samples), but
// recursive, in double precision, single-threaded, with brute-force
// intersection. For small images of small scenes. The routines it shares
// with the renderer (camera_frame, flatten, scene_at,
// expand_emissive_lights, orthonormal_basis and sampling.h's samples,
// filters, lens and dimensions) are each tested against their closed form
// (render_inputs_test.cpp, sampling_test.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include "rtcl/render/image.hpp"
#include "rtcl/render/renderer.hpp"
#include "rtcl/scene/scene_description.hpp"

namespace rtcl::test {

struct ReferenceImage {
  Image image;
  // Per pixel, 1 where the pixel's ray tree (the primitive every ray hits
  // and every shadow ray's outcome) changes when its sample positions move
  // by `ambiguity_px` pixels: the image is discontinuous there, and float
  // and double may legitimately pick different sides.
  std::vector<std::uint8_t> ambiguous;
};

ReferenceImage reference_render(const SceneDescription& scene, const RenderSettings& settings, double ambiguity_px = 0.01);

struct ImageDifference {
  double rmse = 0.0;                 // over all pixels and channels
  double max_error = 0.0;            // largest |a - b| of any channel
  double max_error_unmasked = 0.0;   // the same over pixels the mask does not mark
  std::size_t masked_pixels = 0;
  std::size_t pixels_over = 0;           // pixels with some channel off by more than `over`
  std::size_t pixels_over_unmasked = 0;  // ... of those, not marked by the mask
};

// a and b must have the same size; `mask` (1 = excused: ambiguous, edge) may
// be empty.
ImageDifference compare_images(const Image& a, const Image& b, const std::vector<std::uint8_t>& mask = {},
                               double over = 0.05);

// Pixels within `radius` pixels of an edge of `image`: some pixel in the
// (2 radius + 1)^2 square around differs by more than `step` in a channel.
std::vector<std::uint8_t> edge_pixels(const Image& image, double step = 0.05, int radius = 1);

}  // namespace rtcl::test
