// RMSE and SSIM of display values against closed forms: identical images,
// constants, a constant offset (SSIM's luminance term alone, the moments
// from the 2D Gaussian window written out here), clamping and bad sizes.
#include "rtcl/render/image_metrics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "rtcl/error.hpp"

namespace rtcl::test {
namespace {

Image filled(std::uint32_t w, std::uint32_t h, float v) {
  Image im;
  im.width = w;
  im.height = h;
  im.rgb.assign(std::size_t(w) * h * 3, v);
  return im;
}

Image noise(std::uint32_t w, std::uint32_t h, float lo, float hi, unsigned seed) {
  Image im = filled(w, h, 0.0f);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(lo, hi);
  for (float& v : im.rgb) v = u(rng);
  return im;
}

const double c1 = 1e-4, c2 = 9e-4;  // (0.01 L)^2, (0.03 L)^2, L = 1

TEST(ImageMetrics, IdenticalImagesHaveSsimOne) {
  Image a = noise(16, 13, 0.0f, 1.0f, 1);
  EXPECT_NEAR(display_ssim(a, a), 1.0, 1e-12);
  EXPECT_EQ(display_rmse(a, a), 0.0);
}

// No variance: SSIM = (2ab + C1) / (a^2 + b^2 + C1) (the structure term is C2 / C2).
TEST(ImageMetrics, ConstantImages) {
  for (auto [fa, fb] : {std::pair{0.2f, 0.6f}, std::pair{0.0f, 1.0f}, std::pair{0.5f, 0.5f}}) {
    const double a = fa, b = fb;
    const double expect = (2 * a * b + c1) / (a * a + b * b + c1);
    EXPECT_NEAR(display_ssim(filled(12, 11, float(a)), filled(12, 11, float(b))), expect, 1e-12) << a << " " << b;
    EXPECT_NEAR(display_rmse(filled(12, 11, float(a)), filled(12, 11, float(b))), std::abs(a - b), 1e-7);
  }
  // Display values: both sides clamp to 1.
  EXPECT_NEAR(display_ssim(filled(11, 11, 3.0f), filled(11, 11, 17.0f)), 1.0, 1e-12);
}

// b = a + d: equal variances and covariance, so SSIM is the luminance term
// (2 mu (mu + d) + C1) / (mu^2 + (mu + d)^2 + C1) with mu the window's
// weighted mean; an 11x11 image has one window, weights
// exp(-(i^2 + j^2) / (2 * 1.5^2)) normalised.
TEST(ImageMetrics, ConstantOffsetIsTheLuminanceTerm) {
  const float d = 0.15f;
  Image a = noise(11, 11, 0.1f, 0.8f, 7), b = a;
  for (float& v : b.rgb) v += d;
  double expect = 0.0;
  for (int ch = 0; ch < 3; ++ch) {
    double sum_w = 0.0, mu = 0.0;
    for (int y = 0; y < 11; ++y)
      for (int x = 0; x < 11; ++x) {
        const double w = std::exp(-((x - 5) * (x - 5) + (y - 5) * (y - 5)) / (2 * 1.5 * 1.5));
        sum_w += w;
        mu += w * a.rgb[(y * 11 + x) * 3 + ch];
      }
    mu /= sum_w;
    expect += (2 * mu * (mu + d) + c1) / (mu * mu + (mu + d) * (mu + d) + c1) / 3.0;
  }
  EXPECT_NEAR(display_ssim(a, b), expect, 1e-6);  // b's floats hold a + d to 1e-7
  EXPECT_LT(display_ssim(a, b), 1.0);
}

TEST(ImageMetrics, NoiseLowersSsimMonotonically) {
  Image a = noise(24, 24, 0.2f, 0.8f, 3);
  double previous = 1.0;
  for (float amount : {0.02f, 0.1f, 0.3f}) {
    Image b = a, n = noise(24, 24, -amount, amount, 9);
    for (std::size_t i = 0; i < b.rgb.size(); ++i) b.rgb[i] += n.rgb[i];
    const double s = display_ssim(a, b);
    EXPECT_LT(s, previous) << amount;
    previous = s;
  }
}

TEST(ImageMetrics, BadSizesAreErrors) {
  EXPECT_THROW(display_ssim(filled(12, 12, 0), filled(12, 13, 0)), Error);
  EXPECT_THROW(display_ssim(filled(10, 12, 0), filled(10, 12, 0)), Error);
  EXPECT_THROW(display_rmse(filled(4, 4, 0), filled(5, 4, 0)), Error);
}

}  // namespace
}  // namespace rtcl::test
