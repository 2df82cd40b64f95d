// Errors of an image against a reference, on display values: every channel
// clamped to [0, 1] (what an 8-bit file shows; an emitter's radiance, e.g.
// 17 for the Cornell box lamp, would otherwise dominate). For the
// speed/accuracy benchmarks (bench/) and their tests.
#pragma once

#include "rtcl/render/image.hpp"

namespace rtcl {

// Root mean square difference over all pixels and channels. Throws Error
// when the sizes differ.
double display_rmse(const Image& a, const Image& b);

// The structural similarity index (Wang, Bovik, Sheikh & Simoncelli 2004,
// "Image quality assessment: from error visibility to structural
// similarity", eq. 13): per channel and per window position,
//   SSIM = (2 mu_a mu_b + C1)(2 sigma_ab + C2) / ((mu_a^2 + mu_b^2 + C1)(sigma_a^2 + sigma_b^2 + C2)),
// the moments weighted by the paper's 11x11 circular-symmetric Gaussian
// window (sigma 1.5 px, normalised to sum 1), C1 = (0.01 L)^2,
// C2 = (0.03 L)^2, L = 1; averaged over the windows that lie inside the
// image and over the three channels. 1 for identical images. Throws Error
// when the sizes differ or the image is smaller than 11 x 11.
double display_ssim(const Image& a, const Image& b);

}  // namespace rtcl
