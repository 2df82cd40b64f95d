// Runs the built `rtcl` binary as a subprocess, with good and bad inputs in a
// temporary directory, and checks exit codes, messages and output files.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "rtcl/io/ray_file.hpp"
#include "rtcl/accel/structure_kernels.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/fixtures.hpp"
#include "support/reference.hpp"
#include "support/cli_run.hpp"
#include "support/temp_dir.hpp"

namespace rtcl::test {
namespace {

// Two triangles forming a unit quad at z = 0 plus a tetrahedron above it.
const char* const small_obj =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.2 0.2 0.5\nv 0.8 0.2 0.5\nv 0.5 0.8 0.5\nv 0.5 0.4 0.9\n"
    "o floor\nf 1 2 3 4\no tetra\nf 5 6 7\nf 5 6 8\nf 6 7 8\nf 7 5 8\n";

struct Inputs {
  TempDir dir;
  std::string mesh, rays;
  std::vector<Ray> ray_list;
  Inputs() {
    mesh = dir.write("scene.obj", small_obj);
    Geometry g = load_mesh(mesh).geometry;
    ray_list = random_rays(g, 400, 7);
    rays = dir.file("scene.rays");
    write_rays(rays, ray_list);
  }
};

TEST(Cli, NoArgumentsShowsUsageAndFails) {
  TempDir dir;
  CliRun run = run_cli(dir, {});
  EXPECT_EQ(run.status, 2);
  EXPECT_NE(run.err.find("rtcl: error: no subcommand given"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("trace"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("devices"), std::string::npos) << run.err;
}

TEST(Cli, TraceWithoutOutputIsAUsageError) {
  Inputs in;
  expect_usage_error(run_cli(in.dir, {"trace", in.mesh, in.rays}), "--output: missing (required)");
}

// Every bad command line: one "rtcl: error:" line naming the option or
// argument, a pointer to --help, exit 2 (docs/cli.md, "Exit codes");
// nothing is written.
TEST(CliErrors, UsageErrorsAreOneLineAndExit2) {
  Inputs in;
  std::vector<std::string> trace = {"trace", in.mesh, in.rays, "-o", "out.hits"};
  auto with = [](std::vector<std::string> base, std::vector<std::string> extra) {
    base.insert(base.end(), extra.begin(), extra.end());
    return base;
  };
  expect_usage_error(run_cli(in.dir, {"render", "--width", "0", "-o", "x.png"}), "--width 0: must be an integer in [1, 65536]");
  expect_usage_error(run_cli(in.dir, {"render", "--width", "abc", "-o", "x.png"}), "--width");
  expect_usage_error(run_cli(in.dir, {"render", "--spp"}), "--spp");
  expect_usage_error(run_cli(in.dir, {"render", "--accel", "nope", "-o", "x.png"}),
                     "--accel nope: unknown acceleration structure 'nope' (known: brute");
  expect_usage_error(run_cli(in.dir, with(trace, {"--accel", "nope"})),
                     "--accel nope: unknown acceleration structure 'nope' (known: brute");
  expect_usage_error(run_cli(in.dir, with(trace, {"--frobnicate"})), "--frobnicate: unknown option");
  expect_usage_error(run_cli(in.dir, {"trace", "--frobnicate"}), "--frobnicate: unknown option");
  expect_usage_error(run_cli(in.dir, with(trace, {"extra"})), "extra: unexpected argument");
  expect_usage_error(run_cli(in.dir, {"trace", in.mesh}), "RAYS: missing (required)");
  expect_usage_error(run_cli(in.dir, with(trace, {"--repeat", "0"})), "--repeat 0: must be an integer in [1, 1000000]");
  expect_usage_error(run_cli(in.dir, {"no-such-command"}), "no-such-command: unknown subcommand (known: devices");
  EXPECT_FALSE(std::filesystem::exists(in.dir.file("out.hits")));
  EXPECT_FALSE(std::filesystem::exists(in.dir.file("x.png")));
}

TEST(Cli, HelpExits0) {
  TempDir dir;
  for (const char* command : {"trace", "render", "devices"}) {
    CliRun run = run_cli(dir, {command, "--help"});
    EXPECT_EQ(run.status, 0) << command << ": " << run.err;
    EXPECT_NE(run.out.find("Usage: rtcl " + std::string(command)), std::string::npos) << run.out;
  }
}

TEST(Cli, DevicesListsTheTestDevice) {
  TempDir dir;
  CliRun run = run_cli(dir, {"devices"});
  EXPECT_EQ(run.status, 0) << run.err;
  EXPECT_NE(run.out.find("[0] "), std::string::npos) << run.out;
  EXPECT_NE(run.out.find(test_device().info().name), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("max allocation"), std::string::npos) << run.out;
}

TEST(Cli, NoOpenClDeviceIsAClearError) {
  Inputs in;
  TempDir no_vendors;
  std::string env = "OCL_ICD_VENDORS=" + shell_quoted(no_vendors.path());
  expect_failure(run_cli(in.dir, {"devices"}, env), "no OpenCL device found", in.dir);
  expect_failure(run_cli(in.dir, {"trace", in.mesh, in.rays, "-o", "out.hits"}, env), "no OpenCL device found", in.dir,
                 "out.hits");
}

TEST(Cli, TraceMatchesTheReference) {
  Inputs in;
  Geometry g = load_mesh(in.mesh).geometry;
  for (const std::string accel : {"", "brute"}) {
    for (bool any : {false, true}) {
      std::vector<std::string> args = {"trace", in.mesh, in.rays, "-o", "out.hits"};
      if (!accel.empty()) args.insert(args.end(), {"--accel", accel});
      if (any) args.push_back("--any");
      CliRun run = run_cli(in.dir, args);
      ASSERT_EQ(run.status, 0) << run.err;
      EXPECT_EQ(run.err, "");
      EXPECT_NE(run.out.find(test_device().info().name), std::string::npos) << run.out;
      EXPECT_NE(run.out.find("Mrays/s"), std::string::npos) << run.out;
      EXPECT_NE(run.out.find("built in"), std::string::npos) << run.out;
      std::vector<Hit> hits = read_hits(in.dir.file("out.hits"));
      ASSERT_EQ(hits.size(), in.ray_list.size());
      std::size_t failures = 0, hit_count = 0;
      auto report = judge_all(g, in.ray_list, hits, any ? Query::any : Query::closest, &failures);
      EXPECT_EQ(failures, 0u) << (report.empty() ? "" : report[0]) << " (accel '" << accel << "', any " << any << ")";
      for (const Hit& h : hits) hit_count += h.prim >= 0;
      EXPECT_GT(hit_count, in.ray_list.size() / 4) << "the rays aim at the mesh";
    }
  }
}

// --repeat N: N warm launches, their min / median / max times in order, and
// the answers of the last still the reference's.
TEST(Cli, RepeatedTraceReportsMinMedianMaxAndMatchesTheReference) {
  Inputs in;
  Geometry g = load_mesh(in.mesh).geometry;
  CliRun run = run_cli(in.dir, {"trace", in.mesh, in.rays, "-o", "out.hits", "--repeat", "5"});
  ASSERT_EQ(run.status, 0) << run.err;
  std::size_t at = run.out.find(": min ");
  ASSERT_NE(at, std::string::npos) << run.out;
  double lo = 0, mid = 0, hi = 0;
  unsigned launches = 0;
  ASSERT_EQ(std::sscanf(run.out.c_str() + at, ": min %lf / median %lf / max %lf ms over %u warm launches", &lo, &mid,
                        &hi, &launches),
            4)
      << run.out;
  EXPECT_EQ(launches, 5u);
  EXPECT_LE(lo, mid);
  EXPECT_LE(mid, hi);
  std::vector<Hit> hits = read_hits(in.dir.file("out.hits"));
  ASSERT_EQ(hits.size(), in.ray_list.size());
  std::size_t failures = 0;
  auto report = judge_all(g, in.ray_list, hits, Query::closest, &failures);
  EXPECT_EQ(failures, 0u) << (report.empty() ? "" : report[0]);
}

// --coherent: the default structure traces 8-ray packets on a CPU device
// and one ray per work-item on others (packets_for_coherent_calls); the
// answers stay the reference's. --scattered: a single launch sorts on the
// device first on a CPU device (later ones take the way measured faster),
// the answers the reference's; not with --coherent.
// Without either, one ray per work-item (occlusion: in runs).
TEST(Cli, CoherentTraceUsesPacketsAndMatchesTheReference) {
  Inputs in;
  Geometry g = load_mesh(in.mesh).geometry;
  const char* coherent_form =
      packets_for_coherent_calls(test_device().info()) ? "8-ray packets" : "one ray per work-item";
  for (bool any : {false, true}) {
    std::vector<std::string> args = {"trace", in.mesh, in.rays, "-o", "out.hits", "--coherent"};
    if (any) args.push_back("--any");
    CliRun run = run_cli(in.dir, args);
    ASSERT_EQ(run.status, 0) << run.err;
    EXPECT_NE(run.out.find(coherent_form), std::string::npos) << run.out;
    std::vector<Hit> hits = read_hits(in.dir.file("out.hits"));
    ASSERT_EQ(hits.size(), in.ray_list.size());
    std::size_t failures = 0;
    auto report = judge_all(g, in.ray_list, hits, any ? Query::any : Query::closest, &failures);
    EXPECT_EQ(failures, 0u) << (report.empty() ? "" : report[0]) << " (any " << any << ")";
  }
  // --scattered: sorted first on a CPU device, answers the reference's
  const bool sorts = test_device().info().type == "cpu";
  for (const char* repeat : {"1", "4"})
  for (bool any : {false, true}) {
    std::vector<std::string> args = {"trace", in.mesh, in.rays, "-o", "out.hits", "--scattered", "--repeat", repeat};
    if (any) args.push_back("--any");
    CliRun run = run_cli(in.dir, args);
    ASSERT_EQ(run.status, 0) << run.err;
    if (std::string(repeat) == "1")
      EXPECT_EQ(run.out.find("sorted on the device, then one ray per work-item") != std::string::npos, sorts)
          << run.out;
    else
      EXPECT_NE(run.out.find("one ray per work-item"), std::string::npos) << run.out;
    std::size_t failures = 0;
    auto report = judge_all(g, in.ray_list, read_hits(in.dir.file("out.hits")), any ? Query::any : Query::closest,
                            &failures);
    EXPECT_EQ(failures, 0u) << (report.empty() ? "" : report[0]) << " (any " << any << ")";
  }
  CliRun both = run_cli(in.dir, {"trace", in.mesh, in.rays, "-o", "out.hits", "--coherent", "--scattered"});
  EXPECT_NE(both.status, 0);
  EXPECT_NE(both.err.find("--scattered"), std::string::npos) << both.err;
  CliRun plain = run_cli(in.dir, {"trace", in.mesh, in.rays, "-o", "out.hits"});
  ASSERT_EQ(plain.status, 0) << plain.err;
  EXPECT_NE(plain.out.find("one ray per work-item"), std::string::npos) << plain.out;
  // occlusion in occluder runs: named in the report, answers still the reference's
  CliRun runs = run_cli(in.dir, {"trace", in.mesh, in.rays, "-o", "out.hits", "--any", "--accel", "bvh:occluder_run=4"});
  ASSERT_EQ(runs.status, 0) << runs.err;
  EXPECT_NE(runs.out.find("one ray per work-item in runs of 4"), std::string::npos) << runs.out;
  std::size_t failures = 0;
  auto report = judge_all(g, in.ray_list, read_hits(in.dir.file("out.hits")), Query::any, &failures);
  EXPECT_EQ(failures, 0u) << (report.empty() ? "" : report[0]);
}

TEST(Cli, EmptyRayFileWritesAnEmptyHitFile) {
  Inputs in;
  in.dir.write("none.rays", "");
  CliRun run = run_cli(in.dir, {"trace", in.mesh, "none.rays", "-o", "none.hits"});
  EXPECT_EQ(run.status, 0) << run.err;
  EXPECT_TRUE(std::filesystem::exists(in.dir.file("none.hits")));
  EXPECT_EQ(read_text(in.dir.file("none.hits")), "");
}

TEST(Cli, ZeroAreaTrianglesAreSkippedAndSaidOnce) {
  Inputs in;
  in.dir.write("flat.obj", std::string(small_obj) + "f 1 2 2\nf 3 3 3\n");
  CliRun run = run_cli(in.dir, {"trace", "flat.obj", in.rays, "-o", "out.hits"});
  EXPECT_EQ(run.status, 0) << run.err;
  EXPECT_EQ(count_of(run.err, "2 zero-area triangles skipped"), 1u) << run.err;
  EXPECT_EQ(read_hits(in.dir.file("out.hits")).size(), in.ray_list.size());
}

TEST(CliErrors, BadMeshes) {
  Inputs in;
  auto trace = [&](const std::string& mesh) { return run_cli(in.dir, {"trace", mesh, in.rays, "-o", "out.hits"}); };
  expect_failure(trace("absent.obj"), "absent.obj: no such mesh file", in.dir, "out.hits");
  in.dir.write("malformed.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n");
  expect_failure(trace("malformed.obj"), "malformed.obj: cannot import mesh: OBJ: Invalid face index", in.dir,
                 "out.hits");
  in.dir.write("nan.obj", "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n");
  expect_failure(trace("nan.obj"), "nan.obj: triangle 0 (object 'defaultobject') has a NaN or infinite vertex", in.dir,
                 "out.hits");
  in.dir.write("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  expect_failure(trace("range.obj"), "range.obj: cannot import mesh: OBJ: vertex index out of range", in.dir,
                 "out.hits");
  in.dir.write("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
  expect_failure(trace("flat.obj"), "flat.obj: empty scene", in.dir, "out.hits");
  in.dir.write("mesh.fbx", "x");
  expect_failure(trace("mesh.fbx"), "unsupported mesh format '.fbx'", in.dir, "out.hits");
}

TEST(CliErrors, BadRayFiles) {
  Inputs in;
  auto trace = [&](const std::string& rays) { return run_cli(in.dir, {"trace", in.mesh, rays, "-o", "out.hits"}); };
  in.dir.write("odd.rays", std::string(33, '\0'));
  expect_failure(trace("odd.rays"), "odd.rays: size 33 bytes is not a multiple of 32", in.dir, "out.hits");
  std::vector<Ray> rays(in.ray_list.begin(), in.ray_list.begin() + 10);
  rays[4].dy = std::numeric_limits<float>::quiet_NaN();
  write_rays(in.dir.file("nan.rays"), rays);
  expect_failure(trace("nan.rays"), "nan.rays: 1 of 10 rays are invalid; the first is ray 4", in.dir, "out.hits");
  rays[4] = in.ray_list[4];
  rays[7].dx = rays[7].dy = rays[7].dz = 0.0f;
  write_rays(in.dir.file("zero.rays"), rays);
  expect_failure(trace("zero.rays"), "ray 7 (byte offset 224): its direction has zero length", in.dir, "out.hits");
  expect_failure(trace("absent.rays"), "absent.rays: no such ray file", in.dir, "out.hits");
}

TEST(CliErrors, UnknownAccelAndDevice) {
  Inputs in;
  std::vector<std::string> base = {"trace", in.mesh, in.rays, "-o", "out.hits"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = base;
    args.insert(args.end(), extra.begin(), extra.end());
    return run_cli(in.dir, args);
  };
  expect_usage_error(with({"--accel", "octopus"}),
                     "--accel octopus: unknown acceleration structure 'octopus' (known: brute");
  expect_failure(with({"--device", "no-such-device-name"}), "--device no-such-device-name: no device name matches",
                 in.dir, "out.hits", 2);
  expect_failure(with({"--device", "99"}), "--device 99: no such device", in.dir, "out.hits", 2);
}

TEST(CliErrors, UnwritableOutputLeavesNothing) {
  Inputs in;
  CliRun run = run_cli(in.dir, {"trace", in.mesh, in.rays, "-o", "missing/dir/out.hits"});
  expect_failure(run, "missing/dir/out.hits: cannot write: directory 'missing/dir' does not exist", in.dir);
  std::filesystem::create_directory(in.dir.file("taken"));
  expect_failure(run_cli(in.dir, {"trace", in.mesh, in.rays, "-o", "taken"}), "taken: cannot write: it is a directory",
                 in.dir);
}

TEST(CliErrors, FailureKeepsAnOldHitFile) {
  Inputs in;
  in.dir.write("out.hits", "previous");
  expect_failure(run_cli(in.dir, {"trace", "absent.obj", in.rays, "-o", "out.hits"}), "no such mesh file", in.dir);
  EXPECT_EQ(read_text(in.dir.file("out.hits")), "previous");
}

}  // namespace
}  // namespace rtcl::test

namespace rtcl::test {
namespace {

// --precision on both commands and "precision" in scene files.
TEST(CliPrecision, EveryLevelTracesAndReportsItself) {
  Inputs in;
  Geometry g = load_mesh(in.mesh).geometry;
  for (Precision level : test_precisions()) {
    std::string name(precision_name(level));
    CliRun run = run_cli(in.dir, {"trace", in.mesh, in.rays, "-o", "out.hits", "--precision", name});
    ASSERT_EQ(run.status, 0) << run.err;
    EXPECT_NE(run.out.find("(" + name + " precision)"), std::string::npos) << run.out;
    std::vector<Hit> hits = read_hits(in.dir.file("out.hits"));
    std::size_t failures = 0;
    judge_all(g, in.ray_list, hits, Query::closest, &failures);
    if (level != Precision::fast) EXPECT_EQ(failures, 0u) << name;
  }
}

TEST(CliPrecision, UnknownLevelIsOneErrorAndNothingIsTraced) {
  Inputs in;
  CliRun trace = run_cli(in.dir, {"trace", in.mesh, in.rays, "-o", "out.hits", "--precision", "precise"});
  expect_failure(trace, "--precision precise: unknown precision level", in.dir, "out.hits", 2);
  EXPECT_EQ(trace.out.find("trace:"), std::string::npos) << trace.out;
  CliRun render = run_cli(in.dir, {"render", "-q", "-o", "out.png", "--width", "16", "--precision", "precise"});
  expect_failure(render, "--precision precise: unknown precision level", in.dir, "out.png", 2);
}

TEST(CliPrecision, SceneFileLevelAndItsErrors) {
  TempDir dir;
  const std::string scene =
      R"({"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0]}, "precision": "LEVEL",
          "lights": [{"position": [0, 2, 2]}], "materials": {"grey": {}},
          "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "grey"}]})";
  auto with_level = [&](const std::string& level) {
    std::string s = scene;
    s.replace(s.find("LEVEL"), 5, level);
    return dir.write("scene-" + level + ".json", s);
  };
  CliRun ok = run_cli(dir, {"render", with_level("exact"), "-q", "-o", "exact.png", "--width", "16"});
  ASSERT_EQ(ok.status, 0) << ok.err;
  EXPECT_NE(ok.out.find("exact precision"), std::string::npos) << ok.out;
  CliRun overridden =
      run_cli(dir, {"render", with_level("exact"), "-q", "-o", "fast.png", "--width", "16", "--precision", "fast"});
  ASSERT_EQ(overridden.status, 0) << overridden.err;
  EXPECT_NE(overridden.out.find("fast precision"), std::string::npos) << overridden.out;
  expect_failure(run_cli(dir, {"render", with_level("wobbly"), "-q", "-o", "bad.png", "--width", "16"}),
                 "precision: unknown precision level 'wobbly'", dir, "bad.png");
}

TEST(CliStructures, ListsEveryStructureWithItsOptions) {
  TempDir dir;
  CliRun run = run_cli(dir, {"structures"});
  ASSERT_EQ(run.status, 0) << run.err;
  for (const StructureSpec& s : structure_specs()) {
    EXPECT_NE(run.out.find(s.name + "  "), std::string::npos) << s.name;
    for (const OptionSpec& o : s.options) EXPECT_NE(run.out.find(o.name), std::string::npos) << o.name;
  }
  EXPECT_NE(run.out.find("default auto"), std::string::npos) << run.out;
}

TEST(CliStructures, TraceTakesStructureOptionsAndRejectsBadOnes) {
  Inputs in;
  Geometry g = load_mesh(in.mesh).geometry;
  CliRun run = run_cli(in.dir, {"trace", in.mesh, in.rays, "-o", "grid.hits", "--accel", "grid:res=3x2x5"});
  ASSERT_EQ(run.status, 0) << run.err;
  std::vector<Hit> hits = read_hits(in.dir.file("grid.hits"));
  std::size_t failures = 0;
  auto report = judge_all(g, in.ray_list, hits, Query::closest, &failures);
  EXPECT_EQ(failures, 0u) << (report.empty() ? "" : report[0]);
  expect_failure(run_cli(in.dir, {"trace", in.mesh, in.rays, "-o", "bad.hits", "--accel", "grid:lambda=-1"}),
                 "--accel grid:lambda=-1: lambda must be > 0", in.dir, "bad.hits", 2);
  expect_failure(run_cli(in.dir, {"trace", in.mesh, in.rays, "-o", "bad.hits", "--accel", "grid:depth=3"}),
                 "unknown option depth", in.dir, "bad.hits", 2);
  expect_failure(run_cli(in.dir, {"render", "-o", "bad.png", "--accel", "grid:res=0x1x1"}), "res must be", in.dir, "",
                 2);
}

}  // namespace
}  // namespace rtcl::test
