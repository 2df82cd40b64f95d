// Wavelet-guided pixel selection (the lecture's 其他技术: 基于小波的像素选取,
// wavelets to choose the important pixels). A coarse pass traces the corners
// of the blocks of side `block` (as selective tracing's first level); the
// orthonormal Haar transform (haar.hpp) of that coarse image (each
// channel's display value, clamped to [0, 1]; padded to a power-of-two
// square by repeating the last row and column) gives every corner an
// importance: the sum, over the detail coefficients whose support contains
// it, of the coefficient's square over its support's point count (the detail
// energy per corner). Haar supports do not overlap, so a step between two
// supports shows only at a coarser level: the importance is summed over the
// transforms of the image and of its copies shifted by one point in x, y and
// both ("cycle spinning", Coifman & Donoho 1995). A block's priority is
// the importance of its four corners times its pixel count (an estimate of
// its interpolation error). Then, in rounds, every block (of every level) in
// one ranking: the most important are cut at their midlines (as selective
// tracing cuts them), spending at most half of the budget left per round (at
// least 256 pixels), and their new corners are traced in one batch; a cut
// block's priority is the squared Haar detail of its own four corners (the
// 2x2 transform) times its pixels. Rounds end when the budget is spent; the
// remaining blocks are interpolated (sparse_image.hpp). A budget of 1 cuts
// every block down to its pixels: the full render.
#pragma once

#include <cstdint>
#include <vector>

#include "rtcl/render/selective.hpp"

namespace rtcl {

struct WaveletSettings {
  // Side of the coarse pass's blocks, pixels (1 .. 256; 1: every pixel is a
  // corner).
  std::uint32_t block = 8;
  // Pixels traced in all, coarse pass included, as a fraction of the
  // image's (0 < budget <= 1; 1 traces every pixel). Must cover the coarse
  // pass. Speed/accuracy knob.
  float budget = 0.25f;
};

// Throws Error naming the setting ("wavelet block", "wavelet budget").
void check_wavelet(const WaveletSettings& s);

// The importance of every point of a coarse image (gw x gh, 3 floats per
// point, display values), row-major, as described above (summed over the
// four shifts).
std::vector<double> haar_importance(const std::vector<float>& rgb, std::uint32_t gw, std::uint32_t gh);

// The wavelet-guided image; never traces more than budget * width * height
// pixels (rounded down). Throws Error naming the budget when the coarse pass
// alone exceeds it.
Image render_wavelet(const PixelTracer& tracer, std::uint32_t width, std::uint32_t height, const WaveletSettings& s,
                     SelectiveStats* stats = nullptr);

// render_wavelet with the device renderer.
Image render_wavelet(Renderer& renderer, const RenderSettings& settings, const WaveletSettings& s,
                     SelectiveStats* stats = nullptr);

}  // namespace rtcl
