// The built-in showcase scene (rtcl/scene/showcase_scene.hpp): every
// distributed effect is present and specialised in, it matches the host
// reference at a tiny size, and `rtcl render --builtin showcase` renders it
// with no files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "rtcl/render/image.hpp"
#include "rtcl/render/renderer.hpp"
#include "rtcl/scene/motion.hpp"
#include "rtcl/scene/showcase_scene.hpp"
#include "support/cli_run.hpp"
#include "support/error_of.hpp"
#include "support/fixtures.hpp"
#include "support/reference_renderer.hpp"
#include "support/temp_dir.hpp"

namespace rtcl::test {
namespace {

TEST(Showcase, HasEveryEffect) {
  SceneDescription s = showcase_scene();
  EXPECT_TRUE(std::any_of(s.lights.begin(), s.lights.end(), [](const Light& l) { return l.area(); }));
  EXPECT_TRUE(std::any_of(s.materials.begin(), s.materials.end(), [](const Material& m) { return m.glossy(); }));
  EXPECT_TRUE(std::any_of(s.materials.begin(), s.materials.end(), [](const Material& m) { return m.transmissive(); }));
  EXPECT_GT(s.camera.aperture, 0.0f);
  EXPECT_TRUE(scene_moves(s));
  Renderer renderer(test_device(), s, "bvh");
  for (const char* d : {"RTCL_HAS_AREA_LIGHTS", "RTCL_HAS_GLOSSY", "RTCL_HAS_REFRACTION", "RTCL_HAS_MOTION"})
    EXPECT_TRUE(has(renderer.defines(), d)) << d;
  EXPECT_NE(error_of([] { builtin_scene("nothing"); }).find("builtin_scene name \"nothing\": unknown built-in scene"), std::string::npos);
}

// The thresholds of distributed_test.cpp (float rounding 1e-3 where the ray
// tree is stable; at most 2% of the pixels over 0.05).
TEST(Showcase, MatchesTheReferenceAtTinySize) {
  SceneDescription scene = showcase_scene();
  RenderSettings s;
  s.width = s.height = 20;
  s.spp = 4;
  s.sampler = Sampler::sobol;
  s.seed = 5;
  s.light_samples = 2;
  ReferenceImage ref = reference_render(scene, s);
  ImageDifference d = compare_images(Renderer(test_device(), scene, "bvh").render(s), ref.image, ref.ambiguous);
  double pixels = double(s.width) * s.height;
  std::printf("[ measure  ] showcase: rmse %.5f, max unambiguous %.2e, ambiguous %zu, over 0.05: %zu of %.0f\n", d.rmse,
              d.max_error_unmasked, d.masked_pixels, d.pixels_over, pixels);
  EXPECT_LE(d.max_error_unmasked, 1e-3);
  EXPECT_LE(d.pixels_over, 0.02 * pixels);
  EXPECT_LT(d.masked_pixels, 0.5 * pixels);
}

TEST(Showcase, RendersFromTheCommandLineWithNoFiles) {
  TempDir dir;
  std::string out = dir.file("showcase.exr");
  CliRun run = run_cli(dir, {"render", "--builtin", "showcase", "-o", out, "--width", "16", "--spp", "2", "-q"});
  ASSERT_EQ(run.status, 0) << run.err;
  Image image = read_image(out);
  EXPECT_EQ(image.width, 16u);
  float peak = *std::max_element(image.rgb.begin(), image.rgb.end());
  EXPECT_GT(peak, 0.1f);
  CliRun both = run_cli(dir, {"render", dir.write("s.json", "{}"), "--builtin", "showcase", "-o", out});
  expect_failure(both, "not both", dir, "", 2);
  expect_usage_error(run_cli(dir, {"render", "--builtin", "nothing", "-o", out}), "--builtin");
}

}  // namespace
}  // namespace rtcl::test
