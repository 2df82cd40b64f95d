// The command line's conventions (docs/cli.md) on the built `rtcl` binary:
// every row of the exit-code table, for each kind of mistake a case that
// must exit 2 (the command line) beside one that must exit 1 (the input or
// the run); the one-line message form; `rtcl --version`; `rtcl` alone; the
// output formats; rates; progress on a terminal; the scenes directory; and
// scenes lit only by emissive triangles.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "rtcl/io/ray_file.hpp"
#include "rtcl/render/image.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/cli_run.hpp"
#include "support/fixtures.hpp"
#include "support/temp_dir.hpp"

namespace rtcl::test {
namespace {

const char* const quad_obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";

// A mesh and a ray file of `count` rays straight down onto it.
struct TraceInputs {
  TempDir dir;
  std::string mesh, rays;
  explicit TraceInputs(std::size_t count = 16) {
    mesh = dir.write("quad.obj", quad_obj);
    std::vector<Ray> list;
    for (std::size_t i = 0; i < count; ++i) {
      float x = (static_cast<float>(i % 4) + 0.5f) / 4.0f, y = (static_cast<float>(i / 4 % 4) + 0.5f) / 4.0f;
      list.push_back(Ray{x, y, 1.0f, 0.0f, 0.0f, -1.0f, 0.0f, 10.0f});
    }
    rays = dir.file("down.rays");
    write_rays(rays, list);
  }
  std::vector<std::string> trace(std::vector<std::string> extra = {}) const {
    std::vector<std::string> args = {"trace", mesh, rays, "-o", "out.hits"};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  }
};

// CLI11's own texts, which the error path rewrites.
const char* const raw_texts[] = {"Value ", "not in range", "At Most", "At Least", "Could not convert", " is required",
                                 "not in {", "excludes", "The following argument"};

// The exit status, exactly one "rtcl: error: <what>: <problem>" line first
// on stderr containing `fragment`, none of CLI11's raw texts, the pointer to
// --help exactly for usage errors (2), and no `output` file.
void expect_exit(const CliRun& run, int status, const std::string& fragment, const TempDir& dir,
                 const std::string& output = "") {
  EXPECT_EQ(run.status, status) << run.err;
  EXPECT_EQ(count_of(run.err, "rtcl: error:"), 1u) << run.err;
  EXPECT_EQ(run.err.rfind("rtcl: error: ", 0), 0u) << "the error is the first line: " << run.err;
  const std::string first = run.err.substr(0, run.err.find('\n'));
  EXPECT_NE(first.find(fragment), std::string::npos) << "expected '" << fragment << "' in: " << first;
  EXPECT_NE(first.find(": ", 13), std::string::npos) << "<what>: <problem>: " << first;
  for (const char* raw : raw_texts) EXPECT_EQ(run.err.find(raw), std::string::npos) << raw << " in: " << run.err;
  EXPECT_EQ(run.err.find("--help") != std::string::npos, status == 2) << run.err;
  if (!output.empty()) EXPECT_FALSE(std::filesystem::exists(dir.file(output))) << output << " was written";
}

std::string no_vendors_env(const TempDir& empty) { return "OCL_ICD_VENDORS=" + shell_quoted(empty.path()); }

TEST(CliExitCodes, UnknownOptionOrSubcommandExits2) {
  TraceInputs in;
  expect_exit(run_cli(in.dir, in.trace({"--frobnicate"})), 2, "--frobnicate: unknown option", in.dir, "out.hits");
  expect_exit(run_cli(in.dir, {"render", "--frobnicate", "-o", "x.png"}), 2, "--frobnicate: unknown option", in.dir,
              "x.png");
  expect_exit(run_cli(in.dir, in.trace({"extra"})), 2, "extra: unexpected argument", in.dir, "out.hits");
  expect_exit(run_cli(in.dir, {"rendr"}), 2, "rendr: unknown subcommand (known: devices, trace, render", in.dir);
  expect_exit(run_cli(in.dir, {"trace", in.mesh}), 2, "RAYS: missing (required)", in.dir);
  expect_exit(run_cli(in.dir, {"trace", in.mesh, in.rays}), 2, "--output: missing (required)", in.dir);
  expect_exit(run_cli(in.dir, in.trace({"--coherent", "--scattered"})), 2, "not with --", in.dir,
              "out.hits");
}

TEST(CliExitCodes, OptionValueOutOfRangeExits2AndWhatTheDeviceCannotHoldExits1) {
  TraceInputs in;
  expect_exit(run_cli(in.dir, {"render", "--width", "0", "-o", "x.png"}), 2,
              "--width 0: must be an integer in [1, 65536]", in.dir, "x.png");
  expect_exit(run_cli(in.dir, {"render", "--width", "abc", "-o", "x.png"}), 2,
              "--width abc: must be an integer in [1, 65536]", in.dir, "x.png");
  expect_exit(run_cli(in.dir, {"render", "--width", "8", "--width", "9", "-o", "x.png"}), 2,
              "--width: given 2 times (at most once)", in.dir, "x.png");
  expect_exit(run_cli(in.dir, {"render", "--seed", "-1", "-o", "x.png"}), 2, "--seed -1: must be an integer", in.dir,
              "x.png");
  expect_exit(run_cli(in.dir, {"render", "--min-weight", "2", "-o", "x.png"}), 2,
              "--min-weight 2: must be a number in [0, 1]", in.dir, "x.png");
  expect_exit(run_cli(in.dir, {"render", "--method", "cone", "-o", "x.png"}), 2,
              "--method cone: unknown method (known: ray, selective, wavelet, beam)", in.dir, "x.png");
  expect_exit(run_cli(in.dir, {"render", "--tile", "12", "-o", "x.png"}), 2, "--tile 12: must be a multiple of 8",
              in.dir, "x.png");
  expect_exit(run_cli(in.dir, in.trace({"--repeat", "0"})), 2, "--repeat 0: must be an integer in [1, 1000000]",
              in.dir, "out.hits");
  expect_exit(run_cli(in.dir, {"bench", "--size", "0", "-o", "b"}), 2, "--size 0: must be an integer", in.dir, "b");
  // In range, but more than the device holds: the run fails (exit 1).
  expect_exit(run_cli(in.dir, in.trace(), "RTCL_MAX_ALLOC_BYTES=64"), 1, "exceed the largest buffer", in.dir,
              "out.hits");
  // More than the host holds during the build: refused before the build and before any output.
  expect_exit(run_cli(in.dir, in.trace(), "RTCL_MAX_HOST_BYTES=64"), 1, "bytes of host memory at its peak, more than "
              "the 64 bytes available", in.dir, "out.hits");
  expect_exit(run_cli(in.dir, {"bench", "--scene", "tetra:levels=1", "-o", "b"}, "RTCL_MAX_HOST_BYTES=64"), 1,
              "bytes of host memory at its peak", in.dir, "b/bench.json");
}

TEST(CliExitCodes, UnknownPrecisionExits2AndOneInASceneFileExits1) {
  TraceInputs in;
  expect_exit(run_cli(in.dir, in.trace({"--precision", "precise"})), 2,
              "--precision precise: unknown precision level (known: fast, robust, exact)", in.dir, "out.hits");
  expect_exit(run_cli(in.dir, {"render", "--precision", "precise", "-o", "x.png"}), 2, "--precision precise", in.dir,
              "x.png");
  expect_exit(run_cli(in.dir, {"bench", "--precision", "medium", "--scene", "tetra:levels=1", "-o", "b"}), 2,
              "--precision medium: unknown precision level", in.dir, "b");
  in.dir.write("wobbly.json", R"({"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0]}, "precision": "wobbly",
      "lights": [{"position": [0, 2, 2]}], "materials": {"m": {}},
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]})");
  expect_exit(run_cli(in.dir, {"render", "wobbly.json", "-o", "x.png", "--width", "8"}), 1,
              "precision: unknown precision level 'wobbly'", in.dir, "x.png");
}

TEST(CliExitCodes, BadStructureOptionExits2AndOneInASceneFileExits1) {
  TraceInputs in;
  expect_exit(run_cli(in.dir, in.trace({"--accel", "grid:lambda=-1"})), 2,
              "--accel grid:lambda=-1: lambda must be > 0", in.dir, "out.hits");
  expect_exit(run_cli(in.dir, in.trace({"--accel", "grid:depth=3"})), 2, "--accel grid:depth=3: unknown option depth",
              in.dir, "out.hits");
  expect_exit(run_cli(in.dir, in.trace({"--accel", "octopus"})), 2,
              "--accel octopus: unknown acceleration structure 'octopus' (known: brute", in.dir, "out.hits");
  expect_exit(run_cli(in.dir, {"render", "-o", "x.png", "--accel", "grid:res=0x1x1"}), 2, "--accel grid:res=0x1x1",
              in.dir, "x.png");
  in.dir.write("accel.json", R"({"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0]}, "accel": "grid:lambda=-1",
      "lights": [{"position": [0, 2, 2]}], "materials": {"m": {}},
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]})");
  expect_exit(run_cli(in.dir, {"render", "accel.json", "-o", "x.png", "--width", "8"}), 1, "accel.json", in.dir,
              "x.png");
}

TEST(CliExitCodes, BadFramesExit2AndAMissingSceneExits1) {
  TempDir dir;
  expect_exit(run_cli(dir, {"render", "--frames", "5:2", "-o", "f_%d.png"}), 2, "--frames 5:2: needs 0 <= A <= B",
              dir);
  expect_exit(run_cli(dir, {"render", "--frames", "3", "-o", "f_%d.png"}), 2, "--frames 3: expected A:B", dir);
  expect_exit(run_cli(dir, {"render", "--frames", "0:2", "-o", "f_%d.png"}), 2,
              "--frames 0:2: default scene has no moving object", dir);
  expect_exit(run_cli(dir, {"render", "--frames", "0:1", "-o", "f.png"}), 2, "--output f.png: with --frames", dir);
  expect_exit(run_cli(dir, {"render", "--frame-time", "0", "-o", "f_%d.png", "--frames", "0:1"}), 2,
              "--frame-time 0: must be a finite number > 0", dir);
  expect_exit(run_cli(dir, {"render", "missing.json", "--frames", "0:1", "-o", "f_%d.png"}), 1, "missing.json", dir);
  EXPECT_TRUE(dir.entries().empty());
}

TEST(CliExitCodes, BadDeviceIndexExits2AndNoOpenClDeviceAtAllExits1) {
  TraceInputs in;
  expect_exit(run_cli(in.dir, in.trace({"--device", "99"})), 2, "--device 99: no such device", in.dir, "out.hits");
  expect_exit(run_cli(in.dir, in.trace({"--device", "no-such-device-name"})), 2,
              "--device no-such-device-name: no device name matches", in.dir, "out.hits");
  expect_exit(run_cli(in.dir, {"render", "--device", "99", "-o", "x.png", "--width", "8"}), 2,
              "--device 99: no such device", in.dir, "x.png");
  expect_exit(run_cli(in.dir, {"bench", "--device", "99", "--scene", "tetra:levels=1", "-o", "b"}), 2,
              "--device 99: no such device", in.dir);
  expect_exit(run_cli(in.dir, in.trace(), "RTCL_DEVICE=99"), 2, "RTCL_DEVICE=99: no such device", in.dir, "out.hits");
  TempDir empty;
  expect_exit(run_cli(in.dir, in.trace({"--device", "0"}), no_vendors_env(empty)), 1, "no OpenCL device found", in.dir,
              "out.hits");
  expect_exit(run_cli(in.dir, {"devices"}, no_vendors_env(empty)), 1, "no OpenCL device found", in.dir);
}

TEST(CliExitCodes, UnsupportedImageExtensionExits2AndAnUnwritableOutputExits1) {
  TempDir dir;
  expect_exit(run_cli(dir, {"render", "-o", "out.xyz", "--width", "8"}), 2,
              "--output out.xyz: unsupported image format '.xyz' (known: .png", dir, "out.xyz");
  // OpenImageIO would write these (an empty file for .term): not formats rtcl names.
  expect_exit(run_cli(dir, {"render", "-o", "out.term", "--width", "8"}), 2, "unsupported image format '.term'", dir,
              "out.term");
  expect_exit(run_cli(dir, {"render", "-o", "out", "--width", "8"}), 2, "--output out: no file extension", dir, "out");
  expect_exit(run_cli(dir, {"render", "--method", "beam", "-o", "beam.gif", "--width", "8"}), 2,
              "unsupported image format '.gif'", dir, "beam.gif");
  expect_exit(run_cli(dir, {"render", "--spp-sweep", "1,2", "-o", "s_%d.txt", "--width", "8"}), 2,
              "unsupported image format '.txt'", dir);
  expect_exit(run_cli(dir, {"render", "-o", "missing/dir/out.png", "--width", "8"}), 1,
              "missing/dir/out.png: cannot write", dir);
  EXPECT_TRUE(dir.entries().empty());
}

TEST(CliExitCodes, MissingOrMalformedInputFileExits1AndAMissingArgumentExits2) {
  TraceInputs in;
  expect_exit(run_cli(in.dir, {"trace", "absent.obj", in.rays, "-o", "out.hits"}), 1, "absent.obj: no such mesh file",
              in.dir, "out.hits");
  in.dir.write("malformed.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n");
  expect_exit(run_cli(in.dir, {"trace", "malformed.obj", in.rays, "-o", "out.hits"}), 1, "malformed.obj: ", in.dir,
              "out.hits");
  in.dir.write("odd.rays", std::string(33, '\0'));
  expect_exit(run_cli(in.dir, {"trace", in.mesh, "odd.rays", "-o", "out.hits"}), 1,
              "odd.rays: size 33 bytes is not a multiple of 32", in.dir, "out.hits");
  in.dir.write("bad.json", "{\"camera\": {\"position\": [0, 0, 5], \"look_at\": [0, 0, 0]}, \"objects\": [}");
  expect_exit(run_cli(in.dir, {"render", "bad.json", "-o", "x.png", "--width", "8"}), 1, "bad.json: malformed JSON",
              in.dir, "x.png");
  expect_exit(run_cli(in.dir, {"bounds", "absent.obj"}), 1, "absent.obj", in.dir);
  expect_exit(run_cli(in.dir, {"bounds"}), 2, "MESH: missing (required)", in.dir);
}

TEST(CliExitCodes, NoSubcommandExits2AndListsThem) {
  TempDir dir;
  CliRun run = run_cli(dir, {});
  EXPECT_EQ(run.status, 2) << run.err;
  EXPECT_EQ(run.err.rfind("rtcl: error: no subcommand given (known: devices, trace, render, structures, bounds, bench)",
                          0),
            0u)
      << run.err;
  EXPECT_EQ(count_of(run.err, "rtcl: error:"), 1u) << run.err;
  for (const char* sub : {"devices", "trace", "render", "structures", "bounds", "bench"})
    EXPECT_NE(run.err.find("\n  " + std::string(sub) + " "), std::string::npos) << sub << " not listed: " << run.err;
  EXPECT_NE(run.err.find("--help"), std::string::npos) << run.err;
  EXPECT_EQ(run.out, "");
  // Options alone name no subcommand either.
  expect_exit(run_cli(dir, {"--frobnicate"}), 2, "--frobnicate: unknown option", dir);
}

TEST(CliExitCodes, HelpAndVersionExit0) {
  TempDir dir;
  for (const char* sub : {"devices", "trace", "render", "structures", "bounds", "bench"}) {
    CliRun run = run_cli(dir, {sub, "--help"});
    EXPECT_EQ(run.status, 0) << sub << ": " << run.err;
    EXPECT_NE(run.out.find("Usage: rtcl " + std::string(sub)), std::string::npos) << run.out;
  }
  CliRun help = run_cli(dir, {"--help"});
  EXPECT_EQ(help.status, 0) << help.err;
  EXPECT_NE(help.out.find("--version"), std::string::npos) << help.out;
}

// --version: the version, the commit and the OpenCL platforms; with no
// OpenCL driver at all it still answers, with 0 platforms.
TEST(CliVersion, NamesVersionCommitAndPlatforms) {
  TempDir dir;
  CliRun run = run_cli(dir, {"--version"});
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_EQ(run.out.rfind("rtcl 0.", 0), 0u) << run.out;
  EXPECT_NE(run.out.find("\ncommit: "), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find("commit: \n"), std::string::npos) << "an empty commit: " << run.out;
  std::size_t at = run.out.find("\nOpenCL platforms: ");
  ASSERT_NE(at, std::string::npos) << run.out;
  EXPECT_GE(std::atoi(run.out.c_str() + at + 19), 1) << "the test device's platform: " << run.out;
  EXPECT_NE(run.out.find(test_device().info().platform), std::string::npos) << run.out;
  EXPECT_EQ(run.err, "");
  TempDir empty;
  CliRun none = run_cli(dir, {"--version"}, no_vendors_env(empty));
  ASSERT_EQ(none.status, 0) << none.err;
  EXPECT_NE(none.out.find("\nOpenCL platforms: 0"), std::string::npos) << none.out;
}

// The structures' defaults as declared: a float default such as 1.3 reads
// 1.3, not the double nearest to the float.
TEST(CliStructures, DefaultsPrintAsWritten) {
  TempDir dir;
  CliRun run = run_cli(dir, {"structures"});
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_NE(run.out.find("default 1.3 "), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find("99999"), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find("00000001"), std::string::npos) << run.out;
}

// --device reads the same in every subcommand that takes it; -o is
// documented in each; the image formats of render's help are those of
// docs/cli.md, and an uncommon one of them is written and reads back.
TEST(CliOptions, DeviceOutputAndFormatsAreDocumentedAlike) {
  TempDir dir;
  for (const char* sub : {"trace", "render", "bench"}) {
    CliRun run = run_cli(dir, {sub, "--help"});
    ASSERT_EQ(run.status, 0) << run.err;
    EXPECT_NE(run.out.find("OpenCL device: an index or a name substring from `rtcl devices` (default: $RTCL_DEVICE"),
              std::string::npos)
        << sub << ": " << run.out;
    EXPECT_NE(run.out.find("-o,--output"), std::string::npos) << sub << ": " << run.out;
    EXPECT_NE(run.out.find("-q,--quiet"), std::string::npos) << sub << ": " << run.out;
  }
  const std::string formats = ".png, .jpg, .jpeg, .tif, .tiff, .bmp, .ppm (8-bit sRGB); .exr, .hdr (linear float)";
  CliRun render = run_cli(dir, {"render", "--help"});
  EXPECT_NE(render.out.find(formats), std::string::npos) << render.out;
  EXPECT_NE(read_text(std::string(RTCL_SOURCE_DIR) + "/docs/cli.md").find(formats), std::string::npos)
      << "docs/cli.md names other formats";
  for (const char* name : {"out.ppm", "out.HDR"}) {
    CliRun run = run_cli(dir, {"render", "-q", "--width", "8", "--height", "6", "-o", name});
    ASSERT_EQ(run.status, 0) << name << ": " << run.err;
    Image image = read_image(dir.file(name));
    EXPECT_EQ(image.width, 8u);
    EXPECT_EQ(image.height, 6u);
  }
  CliRun bench = run_cli(dir, {"bench", "--help"});
  EXPECT_EQ(bench.out.find("/shared/scenes"), std::string::npos) << "a machine's path as default: " << bench.out;
}

// A rate has three significant digits at least: a few rays in a short
// launch never read "0.00 Mrays/s".
TEST(CliRates, SmallRatesKeepSignificantDigits) {
  TraceInputs in(2);
  for (const char* repeat : {"1", "3"}) {
    CliRun run = run_cli(in.dir, in.trace({"--repeat", repeat}));
    ASSERT_EQ(run.status, 0) << run.err;
    std::size_t end = run.out.find(" Mrays/s");
    ASSERT_NE(end, std::string::npos) << run.out;
    std::size_t start = run.out.rfind(' ', end - 1) + 1;
    std::string rate = run.out.substr(start, end - start);
    ASSERT_NE(rate, "-") << "no time measured: " << run.out;
    EXPECT_GT(std::strtod(rate.c_str(), nullptr), 0.0) << run.out;
    std::size_t first = rate.find_first_not_of("0.");
    ASSERT_NE(first, std::string::npos) << rate;
    std::size_t significant = 0;
    for (std::size_t i = first; i < rate.size(); ++i) significant += rate[i] != '.';
    EXPECT_GE(significant, 3u) << rate << " in " << run.out;
  }
}

// Progress on stderr when it is a terminal (a pseudo-terminal from
// script(1)), in trace and bench as in render; never when redirected, nor
// with -q.
TEST(CliProgress, OnATerminalOnly) {
  if (!std::filesystem::exists("/usr/bin/script")) GTEST_SKIP() << "script(1) is not installed";
  TraceInputs in;
  auto on_terminal = [&](const std::vector<std::string>& args) {
    std::string command = shell_quoted(std::string(RTCL_BINARY_DIR) + "/rtcl");
    for (const std::string& a : args) command += " " + shell_quoted(a);
    std::string out = in.dir.file("terminal.txt");
    std::string shell = "cd " + shell_quoted(in.dir.path()) + " && timeout 120 script -qec " + shell_quoted(command) +
                        " /dev/null > " + shell_quoted(out) + " 2>&1";
    EXPECT_EQ(std::system(shell.c_str()), 0) << shell;
    std::string text = read_text(out);
    std::remove(out.c_str());
    return text;
  };
  std::string trace = on_terminal(in.trace({"--repeat", "2"}));
  EXPECT_NE(trace.find("rtcl trace: launch 1 of 2"), std::string::npos) << trace;
  EXPECT_NE(trace.find("hits:"), std::string::npos) << trace;
  std::string quiet = on_terminal(in.trace({"--repeat", "2", "-q"}));
  EXPECT_EQ(quiet.find("rtcl trace:"), std::string::npos) << quiet;
  std::string bench = on_terminal({"bench", "--size", "8", "--scene", "tetra:levels=1", "--accel", "bvh", "--rays",
                                   "primary", "--repeat", "1", "--check-rays", "0", "--no-embree", "-o", "b"});
  EXPECT_NE(bench.find("rtcl bench: [0/"), std::string::npos) << bench;
  CliRun redirected = run_cli(in.dir, {"bench", "--size", "8", "--scene", "tetra:levels=1", "--accel", "bvh", "--rays",
                                       "primary", "--repeat", "1", "--check-rays", "0", "--no-embree", "-o", "b2"});
  ASSERT_EQ(redirected.status, 0) << redirected.err;
  EXPECT_EQ(redirected.err, "");
}

// `rtcl bench` has no scenes directory of its own: a mesh scene needs
// --scenes-dir or $RTCL_SCENES_DIR, and without either the message names
// both; procedural scenes need neither.
TEST(CliScenes, BenchNamesTheFlagAndTheVariableWithoutAScenesDirectory) {
  TempDir dir;
  expect_exit(run_cli(dir, {"bench", "--scene", "bunny", "-o", "b"}, "RTCL_SCENES_DIR="), 2,
              "--scene bunny: a mesh scene, and no scenes directory is given: pass --scenes-dir DIR or set "
              "RTCL_SCENES_DIR",
              dir, "b");
  expect_exit(run_cli(dir, {"bench", "--scene", "bunny", "--scenes-dir", dir.path(), "-o", "b"}), 1,
              "stanford_bunny/bunny.obj not found", dir, "b");
  CliRun from_env = run_cli(dir,
                            {"bench", "--scene", "bunny", "--size", "8", "--accel", "bvh", "--rays", "primary",
                             "--repeat", "1", "--check-rays", "0", "--no-embree", "-o", "b"},
                            "RTCL_SCENES_DIR=" + shell_quoted(scenes_dir()));
  EXPECT_EQ(from_env.status, 0) << from_env.err;
}

// A scene lit only by emissive triangles (the Cornell box's Ke lamp) and
// no light declared: the emissive triangles light it as area lights, the
// image equal to the one with the light {"type": "emissive"} that the note
// names; a scene with no light and nothing emitting, or under --method beam
// (point lights only), gets a warning instead.
TEST(CliEmissive, EmissiveTrianglesLightASceneWithoutLights) {
  TempDir dir;
  const std::string obj = scene_path("cornell_box/CornellBox-Original.obj");
  const std::string camera = R"("camera": {"position": [0, 1, 3.9], "look_at": [0, 1, 0], "fov": 39.3})";
  const std::string objects = R"("objects": [{"type": "mesh", "file": ")" + obj + R"("}])";
  dir.write("implicit.json", "{" + camera + ", " + objects + "}");
  // The lamp's Ke is (17, 12, 4): its brightest channel scaled to 1.
  char intensity[32];
  std::snprintf(intensity, sizeof intensity, "%.9g", static_cast<double>(static_cast<float>(1.0 / 17.0)));
  dir.write("explicit.json", "{" + camera + R"(, "lights": [{"type": "emissive", "intensity": )" +
                                 intensity + "}], " + objects + "}");
  const std::vector<std::string> size = {"--width", "24", "--height", "24", "-q"};
  auto render = [&](const std::string& scene, const std::string& out, std::vector<std::string> extra = {}) {
    std::vector<std::string> args = {"render", scene, "-o", out};
    args.insert(args.end(), size.begin(), size.end());
    args.insert(args.end(), extra.begin(), extra.end());
    return run_cli(dir, args);
  };
  CliRun implicit = render("implicit.json", "implicit.exr");
  ASSERT_EQ(implicit.status, 0) << implicit.err;
  EXPECT_NE(implicit.err.find("rtcl: note: implicit.json: no light declared: its 2 emissive triangles light it as area lights, as "
                              "{\"type\": \"emissive\", \"intensity\": 0.0588}"),
            std::string::npos)
      << implicit.err;
  CliRun explicit_light = render("explicit.json", "explicit.exr");
  ASSERT_EQ(explicit_light.status, 0) << explicit_light.err;
  EXPECT_EQ(explicit_light.err, "") << "a declared light: no note";
  Image a = read_image(dir.file("implicit.exr")), b = read_image(dir.file("explicit.exr"));
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  std::size_t lit = 0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    EXPECT_NEAR(a.rgb[i], b.rgb[i], 1e-5f * (1.0f + b.rgb[i])) << "value " << i;
    if (i % 3 == 0 && a.rgb[i] + a.rgb[i + 1] + a.rgb[i + 2] > 0.03f) ++lit;
  }
  // The walls, floor and blocks are lit, not only the lamp itself.
  EXPECT_GT(lit, a.rgb.size() / 3 / 2) << "of " << a.rgb.size() / 3 << " pixels";

  dir.write("dark.json", R"({"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0]}, "materials": {"m": {}},
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]})");
  CliRun dark = render("dark.json", "dark.png");
  ASSERT_EQ(dark.status, 0) << dark.err;
  EXPECT_NE(dark.err.find("rtcl: warning: dark.json: no light declared and no triangle emits light"),
            std::string::npos)
      << dark.err;
  CliRun beam = render("implicit.json", "beam.png", {"--method", "beam"});
  ASSERT_EQ(beam.status, 0) << beam.err;
  EXPECT_NE(beam.err.find("rtcl: warning: implicit.json: no light declared; --method beam lights by point lights only"),
            std::string::npos)
      << beam.err;
}

}  // namespace
}  // namespace rtcl::test
