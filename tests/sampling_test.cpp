// The sample patterns of kernels/shared/sampling.h: stratification of the
// stratified and Sobol samplers (every stratum or elementary interval holds
// its share), their L2 star discrepancy against the closed form of
// independent uniform points, determinism per seed, the permutations, and
// the Gaussian filter's radial distribution against its closed form.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <set>
#include <vector>

#include "rtcl/render/render_layouts.hpp"

namespace rtcl::test {
namespace {

struct Point {
  double u, v;
};

std::vector<Point> points(std::uint32_t sampler, std::uint32_t seed, std::uint32_t pixel, std::uint32_t dimension,
                          std::uint32_t count) {
  std::vector<Point> out;
  for (std::uint32_t i = 0; i < count; ++i) {
    float u, v;
    rtcl_sample_2d(sampler, seed, pixel, dimension, i, count, &u, &v);
    EXPECT_TRUE(u >= 0.0f && u < 1.0f && v >= 0.0f && v < 1.0f) << u << ", " << v;
    out.push_back({u, v});
  }
  return out;
}

// Points per cell of the cols x rows grid over [0, 1)^2.
std::vector<int> cell_counts(const std::vector<Point>& p, std::uint32_t cols, std::uint32_t rows) {
  std::vector<int> counts(std::size_t(cols) * rows, 0);
  for (const Point& q : p) ++counts[std::size_t(q.v * rows) * cols + std::size_t(q.u * cols)];
  return counts;
}

// L2 star discrepancy of a 2D point set (Warnock 1972): the root mean square,
// over anchored boxes [0, x) x [0, y), of (share of points inside - area).
double l2_star_discrepancy(const std::vector<Point>& p) {
  const double n = double(p.size());
  double a = 0.0, b = 0.0;
  for (const Point& q : p) b += (1.0 - q.u * q.u) * (1.0 - q.v * q.v);
  for (const Point& q : p)
    for (const Point& r : p) a += (1.0 - std::max(q.u, r.u)) * (1.0 - std::max(q.v, r.v));
  return std::sqrt(1.0 / 9.0 - b / (2.0 * n) + a / (n * n));
}

// Pixels, dimensions and seeds the pattern tests sweep.
const std::uint32_t kPixels[] = {0u, 1u, 77u, 4095u, 123457u};
const std::uint32_t kDimensions[] = {RTCL_DIM_PIXEL, RTCL_DIM_LENS, 2u, 9u};
const std::uint32_t kSeeds[] = {0u, 1u, 0xdeadbeefu};

TEST(Sampling, SobolPointsOfAPowerOfTwoFormA0m2Net) {
  for (std::uint32_t m = 0; m <= 8; ++m)
    for (std::uint32_t pixel : kPixels)
      for (std::uint32_t dimension : kDimensions)
        for (std::uint32_t seed : kSeeds) {
          std::vector<Point> p = points(RTCL_SAMPLER_SOBOL, seed, pixel, dimension, 1u << m);
          // every elementary interval of area 2^-m: 2^a columns x 2^(m-a) rows
          for (std::uint32_t a = 0; a <= m; ++a) {
            std::vector<int> counts = cell_counts(p, 1u << a, 1u << (m - a));
            ASSERT_EQ(*std::min_element(counts.begin(), counts.end()), 1)
                << "2^" << m << " points, " << (1u << a) << " columns, pixel " << pixel << ", dim " << dimension;
            ASSERT_EQ(*std::max_element(counts.begin(), counts.end()), 1);
          }
        }
}

TEST(Sampling, StratifiedPointsFillEveryStratum) {
  for (std::uint32_t count : {1u, 2u, 3u, 4u, 7u, 9u, 16u, 24u, 64u, 100u})
    for (std::uint32_t pixel : kPixels)
      for (std::uint32_t dimension : kDimensions)
        for (std::uint32_t seed : kSeeds) {
          std::vector<Point> p = points(RTCL_SAMPLER_STRATIFIED, seed, pixel, dimension, count);
          auto k = static_cast<std::uint32_t>(std::lround(std::sqrt(double(count))));
          std::vector<int> counts = k * k == count ? cell_counts(p, k, k) : cell_counts(p, count, 1);
          EXPECT_EQ(*std::min_element(counts.begin(), counts.end()), 1) << count << " points";
          EXPECT_EQ(*std::max_element(counts.begin(), counts.end()), 1) << count << " points";
          if (k * k != count) {  // Latin hypercube: the rows too
            counts = cell_counts(p, 1, count);
            EXPECT_EQ(*std::max_element(counts.begin(), counts.end()), 1) << count << " points";
          }
        }
  float u, v;
  rtcl_sample_2d(RTCL_SAMPLER_STRATIFIED, 5u, 3u, RTCL_DIM_PIXEL, 0u, 1u, &u, &v);
  EXPECT_EQ(u, 0.5f) << "one sub-pixel sample is the pixel centre";
  EXPECT_EQ(v, 0.5f);
}

// Independent uniform points have E[D^2] = (1/4 - 1/9) / n in 2D (Warnock's
// formula averaged): the random sampler must sit on that closed form, the
// stratified and Sobol samplers well below it.
TEST(Sampling, DiscrepancyOfEachSamplerAgainstIndependentPoints) {
  const std::uint32_t n = 64, sets = 200;
  const double random_expected = std::sqrt((0.25 - 1.0 / 9.0) / n);
  for (std::uint32_t sampler : {RTCL_SAMPLER_RANDOM, RTCL_SAMPLER_STRATIFIED, RTCL_SAMPLER_SOBOL}) {
    double sq = 0.0;
    for (std::uint32_t pixel = 0; pixel < sets; ++pixel) {
      double d = l2_star_discrepancy(points(sampler, 7u, pixel, 3u, n));
      sq += d * d;
    }
    double rms = std::sqrt(sq / sets);
    std::printf("[ measure  ] sampler %u, %u points: rms L2 star discrepancy %.5f (independent points: %.5f)\n",
                sampler, n, rms, random_expected);
    if (sampler == RTCL_SAMPLER_RANDOM) {
      // 200 sets: the mean square's relative standard error is about 10%
      EXPECT_NEAR(rms / random_expected, 1.0, 0.15);
    } else {
      EXPECT_LT(rms, 0.5 * random_expected);
    }
  }
}

TEST(Sampling, PureFunctionOfSeedPixelDimensionAndIndex) {
  for (std::uint32_t sampler : {RTCL_SAMPLER_RANDOM, RTCL_SAMPLER_STRATIFIED, RTCL_SAMPLER_SOBOL}) {
    std::vector<Point> a = points(sampler, 3u, 10u, 4u, 16u), b = points(sampler, 3u, 10u, 4u, 16u);
    std::vector<Point> other_seed = points(sampler, 4u, 10u, 4u, 16u), other_pixel = points(sampler, 3u, 11u, 4u, 16u);
    std::vector<Point> other_dim = points(sampler, 3u, 10u, 5u, 16u);
    int same_seed = 0, same_pixel = 0, same_dim = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].u, b[i].u);
      EXPECT_EQ(a[i].v, b[i].v);
      same_seed += a[i].u == other_seed[i].u;
      same_pixel += a[i].u == other_pixel[i].u;
      same_dim += a[i].u == other_dim[i].u;
    }
    EXPECT_LE(same_seed, 1) << "sampler " << sampler << ": another seed draws other points";
    EXPECT_LE(same_pixel, 1) << "sampler " << sampler << ": another pixel draws other points";
    EXPECT_LE(same_dim, 1) << "sampler " << sampler << ": another dimension draws other points";
  }
}

TEST(Sampling, PermutationsAreBijections) {
  for (std::uint32_t n : {1u, 2u, 3u, 5u, 8u, 100u, 1000u, 4097u})
    for (std::uint32_t key : {0u, 1u, 0x9e3779b9u}) {
      std::set<std::uint32_t> seen;
      for (std::uint32_t i = 0; i < n; ++i) {
        std::uint32_t j = rtcl_permute(i, n, key);
        ASSERT_LT(j, n);
        seen.insert(j);
      }
      EXPECT_EQ(seen.size(), n) << n << ", key " << key;
    }
}

TEST(Sampling, CeilSqrtIsExact) {
  for (std::uint32_t n = 1; n < 70000; ++n)
    ASSERT_EQ(rtcl_ceil_sqrt(n), std::uint32_t(std::ceil(std::sqrt(double(n))))) << n;
  for (std::uint32_t k : {1000u, 46339u, 46340u})
    for (std::uint32_t n : {k * k - 1u, k * k, k * k + 1u})
      EXPECT_EQ(rtcl_ceil_sqrt(n), std::uint32_t(std::ceil(std::sqrt(double(n))))) << n;
  EXPECT_EQ(rtcl_ceil_sqrt(2147483647u), 46341u);
}

// Radially symmetric Gaussian of sigma s truncated at R: P(r < x) =
// (1 - exp(-x^2 / 2s^2)) / (1 - exp(-R^2 / 2s^2)).
TEST(Sampling, GaussianFilterOffsetsFollowTheTruncatedGaussian) {
  const double s = RTCL_GAUSSIAN_SIGMA, R = RTCL_GAUSSIAN_RADIUS;
  const std::uint32_t n = 4096;
  std::vector<Point> p = points(RTCL_SAMPLER_SOBOL, 1u, 2u, RTCL_DIM_PIXEL, n);
  double mean_x = 0.0, mean_y = 0.0;
  std::vector<double> radii;
  for (const Point& q : p) {
    float dx, dy;
    rtcl_filter_offset(RTCL_FILTER_GAUSSIAN, float(q.u), float(q.v), &dx, &dy);
    double r = std::hypot(dx, dy);
    EXPECT_LE(r, R * (1.0 + 1e-6));
    radii.push_back(r);
    mean_x += dx / n;
    mean_y += dy / n;
  }
  EXPECT_NEAR(mean_x, 0.0, 0.01);
  EXPECT_NEAR(mean_y, 0.0, 0.01);
  for (double x : {0.25, 0.5, 1.0}) {
    double expected = (1.0 - std::exp(-x * x / (2 * s * s))) / (1.0 - std::exp(-R * R / (2 * s * s)));
    double share = double(std::count_if(radii.begin(), radii.end(), [&](double r) { return r < x; })) / n;
    EXPECT_NEAR(share, expected, 0.005) << "radius " << x;
  }
  float dx, dy;
  rtcl_filter_offset(RTCL_FILTER_BOX, 0.25f, 0.75f, &dx, &dy);
  EXPECT_EQ(dx, -0.25f);
  EXPECT_EQ(dy, 0.25f);
}

}  // namespace
}  // namespace rtcl::test
