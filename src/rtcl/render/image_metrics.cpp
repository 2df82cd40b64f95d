#include "rtcl/render/image_metrics.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "rtcl/error.hpp"

namespace rtcl {

namespace {

void check_same_size(const Image& a, const Image& b, const char* metric) {
  if (a.width != b.width || a.height != b.height || a.rgb.size() != b.rgb.size() ||
      a.rgb.size() != std::size_t(a.width) * a.height * 3)
    throw Error(std::string(metric) + ": images of " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                " and " + std::to_string(b.width) + "x" + std::to_string(b.height) + " pixels: sizes must match");
}

double display(float v) { return std::clamp(double(v), 0.0, 1.0); }

constexpr int kWindow = 11;  // Wang et al. 2004: 11 x 11, sigma 1.5
constexpr double kSigma = 1.5;

std::array<double, kWindow> gaussian_1d() {
  std::array<double, kWindow> w{};
  double sum = 0.0;
  for (int i = 0; i < kWindow; ++i) {
    const double d = i - kWindow / 2;
    w[i] = std::exp(-d * d / (2.0 * kSigma * kSigma));
    sum += w[i];
  }
  for (double& v : w) v /= sum;
  return w;
}

}  // namespace

double display_rmse(const Image& a, const Image& b) {
  check_same_size(a, b, "RMSE");
  double sq = 0.0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    const double e = display(a.rgb[i]) - display(b.rgb[i]);
    sq += e * e;
  }
  return a.rgb.empty() ? 0.0 : std::sqrt(sq / double(a.rgb.size()));
}

double display_ssim(const Image& a, const Image& b) {
  check_same_size(a, b, "SSIM");
  if (a.width < kWindow || a.height < kWindow)
    throw Error("SSIM: an image of " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                " pixels is smaller than the 11x11 window");
  const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
  // The 2D window is the outer product of the 1D one (the Gaussian is separable).
  const std::array<double, kWindow> g = gaussian_1d();
  const std::uint32_t ow = a.width - kWindow + 1, oh = a.height - kWindow + 1;
  double total = 0.0;
  for (int ch = 0; ch < 3; ++ch)
    for (std::uint32_t y0 = 0; y0 < oh; ++y0)
      for (std::uint32_t x0 = 0; x0 < ow; ++x0) {
        double ma = 0, mb = 0, aa = 0, bb = 0, ab = 0;
        for (int j = 0; j < kWindow; ++j)
          for (int i = 0; i < kWindow; ++i) {
            const std::size_t p = (std::size_t(y0 + j) * a.width + x0 + i) * 3 + ch;
            const double w = g[j] * g[i], va = display(a.rgb[p]), vb = display(b.rgb[p]);
            ma += w * va;
            mb += w * vb;
            aa += w * va * va;
            bb += w * vb * vb;
            ab += w * va * vb;
          }
        const double sa = aa - ma * ma, sb = bb - mb * mb, sab = ab - ma * mb;
        total += (2 * ma * mb + c1) * (2 * sab + c2) / ((ma * ma + mb * mb + c1) * (sa + sb + c2));
      }
  return total / (3.0 * double(ow) * oh);
}

}  // namespace rtcl
