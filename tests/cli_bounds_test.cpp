// `rtcl bounds MESH [--json]` (src/cli/bounds_command.cpp), run as the built
// binary: every volume printed, JSON that parses and agrees with an
// independent AABB of the file's vertices, one clear error for bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "support/cli_run.hpp"
#include "support/temp_dir.hpp"

namespace rtcl::test {
namespace {

// A unit cube's corners plus one vertex at (2, 0.5, 0.5): AABB [0, 2] x [0, 1]^2.
const char* const cube_and_wedge_obj =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nv 2 0.5 0.5\n"
    "f 1 2 3 4\nf 5 6 7 8\nf 1 2 6 5\nf 4 3 7 8\nf 2 9 3\nf 6 9 7\n";

TEST(CliBounds, PrintsEveryVolume) {
  TempDir dir;
  std::string mesh = dir.write("cube.obj", cube_and_wedge_obj);
  CliRun run = run_cli(dir, {"bounds", mesh});
  ASSERT_EQ(run.status, 0) << run.err;
  for (const char* name : {"aabb", "obb", "kdop4", "kdop7", "kdop9", "kdop13", "ritter", "iterated", "exact", "axis 2"})
    EXPECT_NE(run.out.find(name), std::string::npos) << name << "\n" << run.out;
}

TEST(CliBounds, JsonAgreesWithTheVertices) {
  TempDir dir;
  std::string mesh = dir.write("cube.obj", cube_and_wedge_obj);
  CliRun run = run_cli(dir, {"bounds", mesh, "--json"});
  ASSERT_EQ(run.status, 0) << run.err;
  nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["points"], 9);
  const nlohmann::json& v = j["volumes"];
  EXPECT_DOUBLE_EQ(v["aabb"]["volume"].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(v["aabb"]["area"].get<double>(), 10.0);
  EXPECT_DOUBLE_EQ(v["aabb"]["volume_vs_aabb"].get<double>(), 1.0);
  EXPECT_EQ(v["obb"]["axes"].size(), 3u);
  EXPECT_LE(v["obb"]["area_vs_aabb"].get<double>(), 1.0 + 1e-6);
  EXPECT_EQ(v["kdop13"]["slabs"].size(), 13u);
  // The exact radius is at most Ritter's and at least half the largest
  // distance between two vertices, |(0,0,0) - (2,.5,.5)| / 2.
  double exact = v["exact"]["radius"].get<double>();
  EXPECT_LE(exact, v["ritter"]["radius"].get<double>() * (1 + 1e-6));
  EXPECT_GE(exact, 0.5 * std::sqrt(4.5) * (1 - 1e-6));
  // a measured time: a positive number (steady clock, nanosecond ticks)
  for (const char* name : {"aabb", "obb", "kdop4", "ritter", "exact"}) {
    ASSERT_TRUE(v[name]["build_ms"].is_number()) << name;
    EXPECT_GT(v[name]["build_ms"].get<double>(), 0.0) << name;
  }
}

TEST(CliBounds, BadInputIsOneErrorLine) {
  TempDir dir;
  expect_failure(run_cli(dir, {"bounds", dir.file("missing.obj")}), "missing.obj", dir);
  std::string empty = dir.write("empty.obj", "v 0 0 0\nv 1 0 0\n");
  expect_failure(run_cli(dir, {"bounds", empty}), "empty.obj", dir);
  std::string nan = dir.write("nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n");
  expect_failure(run_cli(dir, {"bounds", nan}), "nan.obj", dir);
  expect_usage_error(run_cli(dir, {"bounds"}), "MESH: missing (required)");
}

}  // namespace
}  // namespace rtcl::test
