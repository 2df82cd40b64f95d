// The Haar transform against closed forms: the coefficients of steps and
// constants, perfect reconstruction and energy preservation (it is
// orthonormal); the importance of a coarse image's points (wavelet.hpp).
#include "rtcl/render/haar.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "rtcl/error.hpp"
#include "rtcl/render/wavelet.hpp"

namespace rtcl::test {
namespace {

// Tolerance: rounding of a few operations per level on values of order `scale`.
double tolerance(double scale, std::size_t n) { return 16.0 * std::log2(double(n) + 1) * 1e-16 * scale; }

// A unit step x_i = 1 for i < m of n = 2^k samples: the average is m / sqrt n;
// the detail of the level-l pair (support 2^l samples starting at s) is
// (ones in the first half - ones in the second half) / 2^(l/2).
TEST(Haar, StepCoefficientsInOneDimension) {
  const std::size_t n = 16;
  for (std::size_t m : {1u, 5u, 8u, 13u}) {
    std::vector<double> x(n);
    for (std::size_t i = 0; i < n; ++i) x[i] = i < m ? 1.0 : 0.0;
    haar_1d(x);
    EXPECT_NEAR(x[0], double(m) / std::sqrt(double(n)), tolerance(4, n)) << m;
    // Details of level l (support 2^l) lie at n / 2^l + s / 2^l.
    for (std::size_t support = 2; support <= n; support *= 2)
      for (std::size_t s = 0; s < n; s += support) {
        auto ones = [&](std::size_t a, std::size_t b) { return double(std::min(std::max(m, a), b) - a); };
        const double expect = (ones(s, s + support / 2) - ones(s + support / 2, s + support)) / std::sqrt(double(support));
        EXPECT_NEAR(x[n / support + s / support], expect, tolerance(4, n)) << "m " << m << " support " << support;
      }
  }
}

TEST(Haar, ConstantAndStepImages) {
  const std::uint32_t n = 8;
  std::vector<double> c(n * n, 0.3);
  haar_2d(c, n);
  EXPECT_NEAR(c[0], 0.3 * n, tolerance(3, n * n));  // sum / n
  for (std::size_t i = 1; i < c.size(); ++i) EXPECT_NEAR(c[i], 0.0, tolerance(3, n * n)) << i;
  // 1 left of the middle: the average n / 2 and the coarsest x detail n / 2
  // (the basis function is +-1/n on the two halves), nothing else.
  for (std::uint32_t y = 0; y < n; ++y)
    for (std::uint32_t x = 0; x < n; ++x) c[y * n + x] = x < n / 2 ? 1.0 : 0.0;
  haar_2d(c, n);
  EXPECT_NEAR(c[0], n / 2.0, tolerance(8, n * n));
  EXPECT_NEAR(c[1], n / 2.0, tolerance(8, n * n));
  for (std::size_t i = 2; i < c.size(); ++i) EXPECT_NEAR(c[i], 0.0, tolerance(8, n * n)) << i;
}

TEST(Haar, PerfectReconstructionAndEnergy) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  std::vector<double> x(64);
  for (double& v : x) v = u(rng);
  for (std::uint32_t n : {1u, 2u, 8u}) {
    std::vector<double> data(x.begin(), x.begin() + n * n), c = data;
    haar_2d(c, n);
    double e0 = 0, e1 = 0;
    for (std::size_t i = 0; i < data.size(); ++i) e0 += data[i] * data[i], e1 += c[i] * c[i];
    EXPECT_NEAR(e1, e0, tolerance(e0, data.size())) << n;
    inverse_haar_2d(c, n);
    for (std::size_t i = 0; i < data.size(); ++i) EXPECT_NEAR(c[i], data[i], tolerance(2, data.size())) << n;
  }
  std::vector<double> c = x;
  haar_1d(c);
  inverse_haar_1d(c);
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(c[i], x[i], tolerance(2, x.size()));
  std::vector<double> bad(6);
  EXPECT_THROW(haar_1d(bad), Error);
  EXPECT_THROW(haar_2d(bad, 3), Error);
}

// A coarse image with a step between columns 4 and 5 (of 8): the finest pair
// that straddles it, columns 4 and 5, carries the most detail energy; a
// constant image has none.
TEST(Haar, ImportanceIsLargestAtTheStep) {
  const std::uint32_t w = 8, h = 5;
  std::vector<float> rgb(w * h * 3);
  for (std::uint32_t y = 0; y < h; ++y)
    for (std::uint32_t x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) rgb[(y * w + x) * 3 + c] = x < 5 ? 1.0f : 0.0f;
  std::vector<double> e = haar_importance(rgb, w, h);
  for (std::uint32_t y = 0; y < h; ++y)
    for (std::uint32_t x = 0; x < w; ++x)
      if (x != 4 && x != 5) EXPECT_LT(e[y * w + x], e[y * w + 4]) << x << ", " << y;
  std::fill(rgb.begin(), rgb.end(), 0.4f);
  // Equal inputs give equal averages at every level: every detail is exactly 0.
  for (double v : haar_importance(rgb, w, h)) EXPECT_EQ(v, 0.0);
}

}  // namespace
}  // namespace rtcl::test
