// Selective tracing with interpolation and its wavelet-guided variant: the
// interpolation against closed forms (a constant and an affine image are
// reproduced exactly), the device renderer's pixel lists against its own
// full render of the same settings (a threshold of 0, a block of 1 and a
// budget of 1 trace every pixel and must give the full image: bit for bit
// at 1 spp, up to the order of float sums at more),
// the traced share against the threshold and the budget, and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>

#include "rtcl/error.hpp"
#include "rtcl/render/renderer.hpp"
#include "rtcl/render/selective.hpp"
#include "rtcl/render/wavelet.hpp"
#include "rtcl/scene/default_scene.hpp"
#include "support/cli_run.hpp"
#include "support/fixtures.hpp"

namespace rtcl::test {
namespace {

// A synthetic image: colour(x, y), one object at depth 1; counts what it traced.
struct Synthetic {
  std::uint32_t width;
  std::function<void(std::uint32_t x, std::uint32_t y, float* rgb)> colour;
  std::uint64_t traced = 0;
  PixelTracer tracer() {
    return [this](const std::vector<std::uint32_t>& pixels) {
      PixelSamples s;
      s.rgb.resize(pixels.size() * 3);
      s.depth.assign(pixels.size(), 1.0f);
      s.object.assign(pixels.size(), 0);
      for (std::size_t i = 0; i < pixels.size(); ++i) colour(pixels[i] % width, pixels[i] / width, &s.rgb[i * 3]);
      traced += pixels.size();
      return s;
    };
  }
};

TEST(Selective, InterpolationIsExactOnAConstantImage) {
  const std::uint32_t w = 37, h = 29;  // neither a multiple of the block
  Synthetic img{w, [](std::uint32_t, std::uint32_t, float* c) { c[0] = 0.25f, c[1] = 0.5f, c[2] = 0.75f; }};
  SelectiveStats stats;
  Image out = render_selective(img.tracer(), w, h, SelectiveSettings{}, &stats);
  for (std::size_t p = 0; p < std::size_t(w) * h; ++p) {
    ASSERT_EQ(out.rgb[p * 3 + 0], 0.25f) << p;
    ASSERT_EQ(out.rgb[p * 3 + 1], 0.5f) << p;
    ASSERT_EQ(out.rgb[p * 3 + 2], 0.75f) << p;
  }
  // Only the first level's corners: columns 0, 8, .., 32, 36; rows 0, 8, .., 24, 28.
  EXPECT_EQ(stats.traced_pixels, 6u * 5u);
  EXPECT_EQ(img.traced, stats.traced_pixels);
  EXPECT_EQ(stats.launches, 1u);
  out = render_wavelet(img.tracer(), w, h, WaveletSettings{8, 0.03f}, &stats);
  for (std::size_t p = 0; p < std::size_t(w) * h; ++p) ASSERT_EQ(out.rgb[p * 3 + 1], 0.5f) << p;
}

// Bilinear (and, on block borders, linear) interpolation is exact for an
// affine image: the error is float rounding of values of about 1 (a few ulp).
TEST(Selective, InterpolationIsExactOnAnAffineImage) {
  const std::uint32_t w = 41, h = 23;
  auto affine = [](std::uint32_t x, std::uint32_t y, int c) { return 0.1 + 0.013 * x * (c + 1) + 0.007 * y * (2 - c); };
  Synthetic img{w, [&](std::uint32_t x, std::uint32_t y, float* c) {
                  for (int k = 0; k < 3; ++k) c[k] = float(affine(x, y, k));
                }};
  SelectiveSettings s;
  s.threshold = 100.0f;  // interpolate every first-level block
  s.block = 16;
  Image out = render_selective(img.tracer(), w, h, s);
  double worst = 0.0;
  for (std::uint32_t y = 0; y < h; ++y)
    for (std::uint32_t x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(out.at(x, y, c) - affine(x, y, c)) / affine(x, y, c));
  EXPECT_LE(worst, 8.0 * std::numeric_limits<float>::epsilon());
}

RenderSettings small_sobol_settings() {
  RenderSettings s;
  s.width = 27;
  s.height = 21;
  s.spp = 1;
  s.sampler = Sampler::sobol;
  s.seed = 3;
  s.light_samples = 2;
  s.batch_pixels = 100;  // several batches per level
  return s;
}

// Every distributed decision at once, so that every sample key is exercised.
SceneDescription busy_scene() {
  SceneDescription scene = default_scene();
  scene.camera.aperture = 0.05f;
  scene.lights.at(0).shape = LightShape::disc;
  scene.lights.at(0).radius = 0.2f;
  scene.lights.at(0).normal = {0.0f, -1.0f, 0.0f};
  for (Material& m : scene.materials)
    if (m.name == "mirror") m.roughness = 0.3f;
  return scene;
}

// Each pixel sums spp * (generations) non-negative float terms, the full
// render per generation into one sum, a pixel list per sample first: the two
// orders differ by at most 2 * terms * FLT_EPSILON of the value.
void expect_same_image(const Image& got, const Image& full, const RenderSettings& s, const std::string& what) {
  ASSERT_EQ(got.rgb.size(), full.rgb.size()) << what;
  if (s.spp == 1) {
    EXPECT_EQ(got.rgb, full.rgb) << what << ": one sample per pixel, bit for bit";
    return;
  }
  const double terms = double(s.spp) * (s.max_depth + 2);
  for (std::size_t i = 0; i < got.rgb.size(); ++i)
    ASSERT_LE(std::abs(double(got.rgb[i]) - full.rgb[i]),
              2.0 * terms * std::numeric_limits<float>::epsilon() * std::abs(double(full.rgb[i])))
        << what << ", value " << i;
}

TEST(Selective, TracingEveryPixelReproducesTheFullRender) {
  Renderer renderer(test_device(), busy_scene(), "bvh");
  for (std::uint32_t spp : {1u, 3u}) {
    RenderSettings settings = small_sobol_settings();
    settings.spp = spp;
    const Image full = renderer.render(settings);
    const std::uint64_t pixels = std::uint64_t(settings.width) * settings.height;
    SelectiveSettings zero;
    zero.threshold = 0.0f;
    SelectiveStats stats;
    expect_same_image(render_selective(renderer, settings, zero, &stats), full, settings, "threshold 0");
    EXPECT_EQ(stats.traced_pixels, pixels);
    EXPECT_LE(stats.launches, 4u) << "one batch per level: 8 -> 4 -> 2 -> 1";
    EXPECT_GT(stats.rays.shadow, 0u);
    SelectiveSettings one;
    one.block = 1;
    one.threshold = 1.0f;
    expect_same_image(render_selective(renderer, settings, one, &stats), full, settings, "block 1");
    EXPECT_EQ(stats.launches, 1u);
    expect_same_image(render_wavelet(renderer, settings, WaveletSettings{8, 1.0f}, &stats), full, settings,
                      "budget 1");
    EXPECT_EQ(stats.traced_pixels, pixels);
  }
}

TEST(Selective, TracedPixelsFallAsTheThresholdRises) {
  Renderer renderer(test_device(), default_scene(), "bvh");
  RenderSettings settings;
  settings.width = settings.height = 48;
  std::uint64_t previous = std::uint64_t(48) * 48 + 1;
  for (float t : {0.0f, 0.02f, 0.1f, 0.3f, 1.0f}) {
    SelectiveSettings s;
    s.threshold = t;
    s.depth_threshold = 1e9f;  // colour and object only
    SelectiveStats stats;
    render_selective(renderer, settings, s, &stats);
    std::printf("[ measure  ] threshold %.2f: %llu of %u pixels traced\n", t, (unsigned long long)stats.traced_pixels,
                48u * 48u);
    EXPECT_LE(stats.traced_pixels, previous) << t;
    if (t > 0.0f) EXPECT_LT(stats.traced_pixels, std::uint64_t(48) * 48) << t;
    previous = stats.traced_pixels;
  }
}

// A vertical step at x = 21: the budget is never exceeded and is spent on
// the blocks that straddle the step.
TEST(Selective, WaveletBudgetIsRespectedAndSpentOnTheStep) {
  const std::uint32_t w = 64, h = 40;
  Synthetic img{w, [](std::uint32_t x, std::uint32_t, float* c) { c[0] = c[1] = c[2] = x < 21 ? 0.9f : 0.1f; }};
  for (float budget : {0.05f, 0.15f, 0.4f, 0.8f}) {
    img.traced = 0;
    SelectiveStats stats;
    Image out = render_wavelet(img.tracer(), w, h, WaveletSettings{8, budget}, &stats);
    EXPECT_LE(stats.traced_pixels, std::uint64_t(std::floor(budget * w * h))) << budget;
    EXPECT_EQ(img.traced, stats.traced_pixels) << budget;
    EXPECT_GE(stats.launches, 2u) << budget;
    if (budget >= 0.15f)  // enough to cut the blocks x = 16 .. 24 down to the step
      for (std::uint32_t y = 0; y < h; ++y) ASSERT_EQ(out.at(20, y, 0), 0.9f) << budget << " row " << y;
  }
  try {
    render_wavelet(img.tracer(), w, h, WaveletSettings{8, 0.01f});
    ADD_FAILURE() << "a budget below the coarse pass accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("wavelet budget"), std::string::npos) << e.what();
  }
}

TEST(Selective, BadSettingsAreClearErrors) {
  auto message = [](auto f) {
    try {
      f();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  SelectiveSettings s;
  s.block = 0;
  EXPECT_NE(message([&] { check_selective(s); }).find("selective block 0"), std::string::npos);
  s = SelectiveSettings{};
  s.threshold = -1.0f;
  EXPECT_NE(message([&] { check_selective(s); }).find("selective threshold"), std::string::npos);
  s = SelectiveSettings{};
  s.depth_threshold = NAN;
  EXPECT_NE(message([&] { check_selective(s); }).find("selective depth threshold"), std::string::npos);
  EXPECT_NE(message([&] { check_wavelet(WaveletSettings{8, 0.0f}); }).find("wavelet budget"), std::string::npos);
  EXPECT_NE(message([&] { check_wavelet(WaveletSettings{300, 0.5f}); }).find("wavelet block"), std::string::npos);
  Renderer renderer(test_device(), default_scene(), "brute");
  RenderSettings r;
  r.width = r.height = 8;
  EXPECT_NE(message([&] { renderer.render_pixels(r, {3, 64}); }).find("pixel 64 is outside the 8x8 image"),
            std::string::npos);
  EXPECT_NE(message([&] { renderer.render_pixels(r, {3, 5, 3}); }).find("pixel 3 is listed twice"), std::string::npos);
}

TEST(Selective, CommandOptions) {
  TempDir dir;
  const std::vector<std::string> base{"render", "--width", "16"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = base;
    args.insert(args.end(), extra.begin(), extra.end());
    return run_cli(dir, args);
  };
  expect_usage_error(with({"-o", "a.png", "--method", "beamish"}), "--method");
  expect_usage_error(with({"-o", "a.png", "--method", "selective", "--selective-block", "0"}), "--selective-block");
  expect_usage_error(with({"-o", "a.png", "--method", "selective", "--selective-threshold", "-1"}),
                     "--selective-threshold");
  expect_usage_error(with({"-o", "a.png", "--method", "selective", "--selective-depth", "nan"}), "--selective-depth");
  expect_usage_error(with({"-o", "a.png", "--method", "wavelet", "--wavelet-budget", "0"}), "--wavelet-budget");
  expect_usage_error(with({"-o", "a.png", "--method", "wavelet", "--wavelet-budget", "0.001"}),
                     "--wavelet-budget 0.001: the coarse pass");
  EXPECT_FALSE(std::filesystem::exists(dir.file("a.png")));
  for (const char* method : {"selective", "wavelet"}) {
    CliRun run = with({"--method", method, "-o", "b.exr", "--accel", "brute"});
    EXPECT_EQ(run.status, 0) << run.err;
    EXPECT_NE(run.out.find(std::string(method) + ": traced"), std::string::npos) << run.out;
  }
}

}  // namespace
}  // namespace rtcl::test
