// `rtcl render --frames A:B` and `--spp-sweep` in one process: frame f is
// the scene with its shutter moved by f * frame time (checked against the
// same scene file with that shutter written out), a sweep's image for k
// samples is the `--spp k` render, and every bad range, list or output
// pattern is one clear error with no output file.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "rtcl/render/image.hpp"
#include "support/cli_run.hpp"
#include "support/temp_dir.hpp"

namespace rtcl::test {
namespace {

// A room corner and a sphere that moves (and grows) over the shutter.
std::string moving_scene(const std::string& shutter) {
  return R"({"camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "aspect": 1)" + shutter + R"(},
    "lights": [{"position": [1, 2, 3]}],
    "materials": {"wall": {"diffuse": 0.7}, "ball": {"diffuse": [0.9, 0.5, 0.1], "specular": 0.3}},
    "objects": [{"type": "sphere", "center": [0, 0, -6], "radius": 5, "material": "wall"},
                {"type": "sphere", "center": [-0.6, 0, 0], "radius": 0.3, "material": "ball",
                 "motion": {"translate": [0.4, 0.1, 0], "scale": 1.1}}]})";
}

std::vector<std::string> args(const std::string& scene, const std::string& output, std::vector<std::string> more) {
  std::vector<std::string> a = {"render", "-q", scene, "--width", "24", "-o", output};
  a.insert(a.end(), more.begin(), more.end());
  return a;
}

std::size_t differing(const Image& a, const Image& b) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) n += a.rgb[i] != b.rgb[i];
  return n;
}

TEST(RenderUnits, FrameFIsTheSceneWithItsShutterMovedByFFrameTimes) {
  TempDir dir;
  std::string scene = dir.write("moving.json", moving_scene(R"(, "shutter": [0, 0.5])"));
  // Default frame time: the shutter's length (abutting shutters).
  CliRun run = run_cli(dir, args(scene, "frame_%03d.exr", {"--frames", "1:2", "--spp", "2"}));
  ASSERT_EQ(run.status, 0) << run.err;
  Image f1 = read_image(dir.file("frame_001.exr")), f2 = read_image(dir.file("frame_002.exr"));
  EXPECT_GT(differing(f1, f2), 20u);
  // Frame 2: shutter [0 + 2 * 0.5, 0.5 + 2 * 0.5], beyond the keyframes.
  std::string shifted = dir.write("shifted.json", moving_scene(R"(, "shutter": [1, 1.5])"));
  ASSERT_EQ(run_cli(dir, args(shifted, "shifted.exr", {"--spp", "2"})).status, 0);
  EXPECT_EQ(differing(f2, read_image(dir.file("shifted.exr"))), 0u);
  // --frame-time 0.75: frame 2's shutter is [1.5, 2].
  ASSERT_EQ(run_cli(dir, args(scene, "timed_%d.exr", {"--frames", "2:2", "--frame-time", "0.75", "--spp", "2"})).status, 0);
  std::string later = dir.write("later.json", moving_scene(R"(, "shutter": [1.5, 2])"));
  ASSERT_EQ(run_cli(dir, args(later, "later.exr", {"--spp", "2"})).status, 0);
  EXPECT_EQ(differing(read_image(dir.file("timed_2.exr")), read_image(dir.file("later.exr"))), 0u);
}

TEST(RenderUnits, SampleSweepImagesAreThoseOfEachSpp) {
  TempDir dir;
  std::string scene = dir.write("moving.json", moving_scene(""));
  ASSERT_EQ(run_cli(dir, args(scene, "sweep_%d.exr", {"--spp-sweep", "1,4"})).status, 0);
  for (const char* spp : {"4"}) {
    std::vector<std::string> plain = args(scene, std::string("plain_") + spp + ".exr", {"--spp", spp});
    ASSERT_EQ(run_cli(dir, plain).status, 0);
    EXPECT_EQ(differing(read_image(dir.file(std::string("sweep_") + spp + ".exr")),
                        read_image(dir.file(std::string("plain_") + spp + ".exr"))),
              0u)
        << spp;
  }
}

TEST(RenderUnits, BadRangesListsAndPatternsAreOneClearError) {
  TempDir dir;
  std::string scene = dir.write("moving.json", moving_scene(""));
  std::string still = dir.write("still.json", R"({"camera": {"position": [0, 0, 4], "look_at": [0, 0, 0]},
    "materials": {"m": {}}, "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]})");
  std::string shrinking = dir.write("shrinking.json", R"({"camera": {"position": [0, 0, 4], "look_at": [0, 0, 0]},
    "materials": {"m": {}}, "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m",
    "motion": {"scale": 0.5}}]})");
  struct Bad {
    std::string scene, output;
    std::vector<std::string> options;
    std::string fragment;
  };
  const std::vector<Bad> cases = {
      {scene, "f_%d.png", {"--frames", "3"}, "--frames 3: expected A:B"},
      {scene, "f_%d.png", {"--frames", "2:1"}, "--frames 2:1: needs 0 <= A <= B"},
      {scene, "f.png", {"--frames", "0:1"}, "needs one %d"},
      {scene, "f_%d.png", {"--frames", "0:1", "--spp-sweep", "1,2"}, "not both"},
      {scene, "f.png", {"--frame-time", "0.5"}, "--frame-time: only with --frames"},
      {still, "f_%d.png", {"--frames", "0:1"}, "no moving object"},
      {shrinking, "f_%d.png", {"--frames", "0:3"}, "frame 1: " + shrinking + ": objects[0].motion"},
      {scene, "s_%d.png", {"--spp-sweep", "0,4"}, "0 is outside 1 .. 65536"},
      {scene, "s_%d.png", {"--spp-sweep", "4,4"}, "4 appears twice"},
  };
  for (const Bad& c : cases) {
    CliRun run = run_cli(dir, args(c.scene, c.output, c.options));
    expect_failure(run, c.fragment, dir, "", 2);  // a bad command line
    for (const auto& name : dir.entries())
      EXPECT_TRUE(name.rfind(".json") == name.size() - 5) << c.fragment << ": left " << name;
  }
}

}  // namespace
}  // namespace rtcl::test
