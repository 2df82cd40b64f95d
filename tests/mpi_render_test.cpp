// `mpirun -np N rtcl render` on localhost (N = 2, 3) against the
// single-process `rtcl render` of the same scene and settings: the same
// pixels bit for bit (EXR keeps the floats), for every tile size and order;
// a rank that fails mid-render is reported and its tile rendered by another;
// a killed rank or a run no rank can finish gives an error and no file.
// Built only with MPI (RTCL_HAVE_MPI); RTCL_MPIEXEC is CMake's MPIEXEC.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "rtcl/render/image.hpp"
#include "support/cli_run.hpp"
#include "support/fixtures.hpp"
#include "support/temp_dir.hpp"

namespace rtcl::test {
namespace {


// As root (CI containers) mpirun needs --allow-run-as-root; --oversubscribe
// lets 3 ranks share 2 cores.
std::string mpirun(int ranks) {
  return shell_quoted(RTCL_MPIEXEC) + " --allow-run-as-root --oversubscribe -np " + std::to_string(ranks);
}

// Small on purpose: spp 4 and depth 5 over the default scene's glass
// sphere, about a second per run.
std::vector<std::string> render_args(const std::string& output) {
  return {"render", "-q", "--width", "64", "--height", "48", "--spp", "4", "-o", output};
}

std::vector<std::string> with(std::vector<std::string> args, const std::vector<std::string>& more) {
  args.insert(args.end(), more.begin(), more.end());
  return args;
}

// For the fault tests: enough work (192 tiles of 8 px, seconds on one rank)
// that every rank is set up and takes tiles before the image is done.
std::vector<std::string> long_render_args(const std::string& output) {
  return {"render", "-q", "--width", "128", "--height", "96", "--spp", "16", "--tile", "8", "-o", output};
}

Image single_process(const TempDir& dir, const std::vector<std::string>& args) {
  CliRun run = run_cli(dir, args);
  EXPECT_EQ(run.status, 0) << run.err;
  return read_image(dir.file(args.back()));
}

Image single_process(const TempDir& dir) {
  CliRun run = run_cli(dir, render_args("single.exr"));
  EXPECT_EQ(run.status, 0) << run.err;
  return read_image(dir.file("single.exr"));
}

void expect_same_pixels(const Image& a, const Image& b, const std::string& what) {
  ASSERT_EQ(a.width, b.width) << what;
  ASSERT_EQ(a.height, b.height) << what;
  std::size_t differing = 0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) differing += a.rgb[i] != b.rgb[i];
  EXPECT_EQ(differing, 0u) << what << ": " << differing << " of " << a.rgb.size() << " values differ";
}

TEST(MpiRender, TwoAndThreeRanksGiveTheSingleProcessImage) {
  TempDir dir;
  Image reference = single_process(dir);
  for (int ranks : {2, 3}) {
    std::string out = "mpi" + std::to_string(ranks) + ".exr";
    CliRun run = run_cli_launched(dir, mpirun(ranks), with(render_args(out), {"--tile", "16"}), mpi_rank_env());
    ASSERT_EQ(run.status, 0) << run.err;
    EXPECT_NE(run.out.find(std::to_string(ranks) + " MPI ranks"), std::string::npos) << run.out;
    for (int r = 0; r < ranks; ++r)
      EXPECT_NE(run.out.find("rank " + std::to_string(r) + " (host"), std::string::npos) << run.out;
    expect_same_pixels(read_image(dir.file(out)), reference, std::to_string(ranks) + " ranks");
  }
}

// The forest's 10,000 bunnies share one mesh: rank 0 broadcasts it once
// (scene bytes keep the sharing) and every rank traces through two levels.
TEST(MpiRender, TheForestOfInstancesGivesTheSingleProcessImage) {
  TempDir dir;
  const std::string scenes = "RTCL_SCENES_DIR=" + shell_quoted(scenes_dir());
  const std::vector<std::string> args{"render", "-q", "--builtin", "forest", "--width", "64", "--height", "36", "--spp", "2"};
  CliRun one = run_cli(dir, with(args, {"-o", "single.exr"}), scenes);
  ASSERT_EQ(one.status, 0) << one.err;
  CliRun run = run_cli_launched(dir, mpirun(2), with(args, {"--tile", "16", "-o", "mpi.exr"}), mpi_rank_env(scenes));
  ASSERT_EQ(run.status, 0) << run.err;
  expect_same_pixels(read_image(dir.file("mpi.exr")), read_image(dir.file("single.exr")), "the forest on 2 ranks");
}

TEST(MpiRender, TileSizeOrderAndSceneSourceDoNotChangeTheImage) {
  TempDir dir;
  Image reference = single_process(dir);
  const std::vector<std::vector<std::string>> variants = {
      {"--tile", "8", "--tile-order", "shuffled"},
      {"--tile", "24", "--tile-order", "rows"},
      {"--tile", "128"},  // one tile larger than the image
      {"--tile", "16", "--tile-order", "shuffled", "--scene-from", "each"}};
  for (const auto& variant : variants) {
    std::string what;
    for (const auto& v : variant) what += v + " ";
    CliRun run = run_cli_launched(dir, mpirun(3), with(render_args("tiled.exr"), variant), mpi_rank_env());
    ASSERT_EQ(run.status, 0) << what << run.err;
    expect_same_pixels(read_image(dir.file("tiled.exr")), reference, what);
  }
}

TEST(MpiRender, ARankFailingMidRenderIsNamedAndItsTileRenderedElsewhere) {
  TempDir dir;
  Image reference = single_process(dir, long_render_args("single.exr"));
  // Rank 2 renders its first tile, then fails instead of returning it.
  CliRun run = run_cli_launched(dir, mpirun(3), long_render_args("faulty.exr"), mpi_rank_env("RTCL_MPI_FAULT=error:2"));
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_NE(run.err.find("rtcl: warning: rank 2 (host "), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("injected fault"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("the job goes to another rank"), std::string::npos) << run.err;
  EXPECT_NE(run.out.find("1 failed"), std::string::npos) << run.out;
  expect_same_pixels(read_image(dir.file("faulty.exr")), reference, "with rank 2 failing");
}

TEST(MpiRender, AKilledRankEndsTheJobWithAnErrorAndNoOutputFile) {
  TempDir dir;
  // Rank 2 sends itself SIGKILL on its first tile: Open MPI's mpirun ends
  // the job, naming the rank, before rank 0 has written anything.
  CliRun run = run_cli_launched(dir, mpirun(3), long_render_args("killed.exr"), mpi_rank_env("RTCL_MPI_FAULT=kill:2"));
  EXPECT_NE(run.status, 0) << run.err;
  EXPECT_NE(run.err.find("rank 2"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("signal 9"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("killed.exr")));
  for (const auto& name : dir.entries()) EXPECT_EQ(name.find(".tmp-"), std::string::npos) << "left behind: " << name;
}

TEST(MpiRender, NoRankAbleToRenderIsOneClearErrorAndNoOutputFile) {
  TempDir dir;
  CliRun run = run_cli_launched(dir, mpirun(2), with(render_args("none.exr"), {"--device", "no-such-device"}), mpi_rank_env());
  EXPECT_EQ(run.status, 1) << run.err;
  EXPECT_EQ(count_of(run.err, "rtcl: error:"), 1u) << run.err;
  EXPECT_NE(run.err.find("every rank failed"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("no-such-device"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("none.exr")));
}

// Animations and sample sweeps: (image, tile) jobs handed out like tiles;
// every image equals the single-process one bit for bit (a moving scene,
// Sobol samples of another seed: what rank 0 decides reaches every rank).
TEST(MpiRender, FramesAndSampleSweepsGiveTheSingleProcessImages) {
  TempDir dir;
  const std::vector<std::string> base = {"render", "-q", "--builtin", "showcase", "--width", "32", "--height", "24",
                                         "--spp", "2", "--sampler", "sobol", "--seed", "3", "--tile", "8"};
  struct Case {
    std::vector<std::string> option;
    std::vector<int> values;
    int ranks;
  };
  for (const Case& c : {Case{{"--frames", "1:3"}, {1, 2, 3}, 3}, Case{{"--spp-sweep", "1,3"}, {1, 3}, 2}}) {
    CliRun single = run_cli(dir, with(with(base, c.option), {"-o", "single_%d.exr"}));
    ASSERT_EQ(single.status, 0) << single.err;
    for (int ranks : {c.ranks}) {
      std::string prefix = "mpi" + std::to_string(ranks) + "_";
      CliRun run = run_cli_launched(dir, mpirun(ranks),
                                    with(with(base, c.option), {"--tile-order", "shuffled", "-o", prefix + "%d.exr"}),
                                    mpi_rank_env());
      ASSERT_EQ(run.status, 0) << run.err;
      EXPECT_NE(run.out.find("in each of " + std::to_string(c.values.size()) + " images"), std::string::npos) << run.out;
      for (int v : c.values)
        expect_same_pixels(read_image(dir.file(prefix + std::to_string(v) + ".exr")),
                           read_image(dir.file("single_" + std::to_string(v) + ".exr")),
                           c.option[0] + " " + std::to_string(v) + ", " + std::to_string(ranks) + " ranks");
    }
  }
}

TEST(MpiRender, BadInputOnRankZeroIsOneErrorForTheWholeJob) {
  TempDir dir;
  CliRun run = run_cli_launched(dir, mpirun(2), {"render", "-q", "missing.json", "-o", "x.png"}, mpi_rank_env());
  EXPECT_EQ(run.status, 1) << run.err;
  EXPECT_EQ(count_of(run.err, "rtcl: error:"), 1u) << run.err;
  EXPECT_NE(run.err.find("missing.json"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("x.png")));
}

}  // namespace
}  // namespace rtcl::test
