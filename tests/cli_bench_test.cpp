// `rtcl bench` on tiny sizes: the JSON holds a complete cell for every
// requested structure, scene and ray set (figures are never asserted), and
// bad input fails with one message before any device work.
#include <gtest/gtest.h>

#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/cli_run.hpp"
#include "support/fixtures.hpp"
#include "support/temp_dir.hpp"

namespace rtcl::test {
namespace {

std::string scenes_env() { return "RTCL_SCENES_DIR=" + shell_quoted(scenes_dir()); }

TEST(CliBench, SmokeRunWritesACompleteMatrix) {
  TempDir dir;
  CliRun run = run_cli(dir,
                       {"bench", "--size", "32", "--scene", "bunny,tetra:levels=2", "--accel", "bvh,grid,bvh-packet",
                        "--repeat", "2", "--check-rays", "64", "--device", "0", "-o", dir.file("out")},
                       scenes_env());
  ASSERT_EQ(run.status, 0) << run.err;
  nlohmann::json json = nlohmann::json::parse(read_text(dir.file("out/bench.json")));
  EXPECT_EQ(json["schema"], "rtcl-bench/1");
  EXPECT_TRUE(json["rtcl"]["commit"].is_string());
  ASSERT_TRUE(json["host"]["cpu"].is_string());
  {
    // the host CPU told apart from others of its model name: family, model
    // and widest vector extension, as the first processor's /proc/cpuinfo
    // entry gives them
    const std::string cpu = json["host"]["cpu"];
    std::istringstream cpuinfo(read_text("/proc/cpuinfo"));
    std::string line, family, flags;
    while (std::getline(cpuinfo, line) && !line.empty()) {
      if (line.rfind("cpu family", 0) == 0) family = line.substr(line.find(':') + 2);
      if (line.rfind("flags", 0) == 0) flags = line + " ";
    }
    if (!family.empty()) EXPECT_NE(cpu.find("family " + family + " model "), std::string::npos) << cpu;
    if (flags.find(" avx512f ") != std::string::npos)
      EXPECT_NE(cpu.find("AVX-512"), std::string::npos) << cpu;
    else if (flags.find(" avx2 ") != std::string::npos)
      EXPECT_NE(cpu.find("AVX2"), std::string::npos) << cpu;
  }
  ASSERT_EQ(json["devices"].size(), 1u);
  EXPECT_TRUE(json["devices"][0]["driver"].is_string());
  EXPECT_EQ(json["options"]["repeat"], 2);
  EXPECT_EQ(json["options"]["diffuse_sort"], "measured");
  // Embree's packet API is measured where Embree traces 8-ray packets natively.
  bool embree_packets = false;
  if (json["embree"].is_object())
    for (const auto& b : json["embree"]["baselines"]) embree_packets = embree_packets || b["packets"].get<bool>();
  std::set<std::tuple<std::string, std::string, std::string>> seen;
  for (const auto& cell : json["cells"]) {
    seen.insert({cell["scene"].get<std::string>(), cell["accel"].get<std::string>(), cell["rays"].get<std::string>()});
    for (const char* field : {"build_ms", "setup_ms", "first_launch_ms", "device_bytes", "bytes_per_primitive"})
      EXPECT_TRUE(cell[field].is_number()) << field << " in " << cell.dump();
    for (const char* timer : {"kernel", "wall"})
      for (const char* stat : {"min", "median", "max"})
        EXPECT_TRUE(cell["mrays_per_s"][timer][stat].is_number()) << timer << " " << stat;
    EXPECT_EQ(cell["kernel_ms_runs"].size(), 2u);
    EXPECT_EQ(cell["wall_ms_runs"].size(), 2u);
    EXPECT_EQ(cell["build_ms_runs"].size(), 2u);  // the build's median is of --repeat builds
    EXPECT_TRUE(cell["check"]["ok"].is_boolean());
    EXPECT_GT(cell["check"]["rays"].get<int>(), 0) << cell.dump();
    EXPECT_EQ(cell["query"], cell["rays"] == "shadow" ? "any" : "closest");
    EXPECT_EQ(cell["precision"], "robust");
    // occlusion in runs: every shadow cell on a CPU device, no other cell
    const bool runs = cell["rays"] == "shadow" && json["devices"][0]["type"] == "cpu";
    EXPECT_EQ(cell["occluder_run"].get<int>(), runs ? 16 : 1) << cell.dump();
    // only scattered calls (the diffuse sets) of single-ray kernels may sort
    const bool may_sort = cell["rays"] == "diffuse" && cell["accel"] != "bvh-packet";
    // of the 2 launches, those that sorted; "sorted" says most of them did
    const int sorted_runs = cell["sorted_runs"].get<int>();
    if (may_sort)
      EXPECT_TRUE(sorted_runs == 0 || sorted_runs == 1 || sorted_runs == 2) << cell.dump();
    else
      EXPECT_EQ(sorted_runs, 0) << cell.dump();
    EXPECT_EQ(cell["sorted"].get<bool>(), 2 * sorted_runs > 2) << cell.dump();
    ASSERT_TRUE(cell.contains("embree"));
#ifdef RTCL_TESTS_EXPECT_EMBREE
    // packets against packets: the packet kernel is compared with rtcIntersect8 / rtcOccluded8
    bool packets = cell["accel"] == "bvh-packet";
    EXPECT_EQ(cell["packets"], packets);
    std::string api = cell["rays"] == "shadow" ? (packets ? "rtcOccluded8" : "rtcOccluded1")
                                               : (packets ? "rtcIntersect8" : "rtcIntersect1");
    if (packets && !embree_packets) {
      EXPECT_TRUE(cell["embree"].is_null()) << cell.dump();
      continue;
    }
    ASSERT_TRUE(cell["embree"].is_object()) << cell.dump();
    EXPECT_EQ(cell["embree"]["api"], api);
    EXPECT_GT(cell["embree"]["ratio"].get<double>(), 0.0) << cell.dump();
    // a build of Embree's after each of the structure's
    EXPECT_EQ(cell["embree"]["build_ms_runs"].size(), 2u);
    EXPECT_GT(cell["embree"]["build_ratio"].get<double>(), 0.0) << cell.dump();
    EXPECT_GT(cell["embree"]["mrays_per_s"]["median"].get<double>(), 0.0);
    // Embree traced the cell's rays after each of its launches
    EXPECT_TRUE(cell["embree"]["paired"].get<bool>());
    EXPECT_EQ(cell["embree"]["trace_ms_runs"].size(), 2u);
#else
    EXPECT_TRUE(cell["embree"].is_null());
#endif
  }
#ifdef RTCL_TESTS_EXPECT_EMBREE
  ASSERT_TRUE(json["embree"].is_object());
  EXPECT_TRUE(json["embree"]["version"].is_string());
  for (const auto& b : json["embree"]["baselines"]) {
    EXPECT_TRUE(b["check"]["ok"].get<bool>()) << b.dump();  // Embree agrees with brute force
    EXPECT_EQ(b["trace_ms_runs"].size(), 2u);
    EXPECT_EQ(b["build_ms_runs"].size(), 2u);
  }
  // scenes x ray sets x {single, packet}
  EXPECT_EQ(json["embree"]["baselines"].size(), 2u * 3u * (embree_packets ? 2u : 1u));
#else
  EXPECT_TRUE(json["embree"].is_null());
#endif
  for (const char* scene : {"bunny", "tetra:levels=2"})
    for (const char* accel : {"bvh", "grid", "bvh-packet"})
      for (const char* rays : {"primary", "shadow", "diffuse"})
        EXPECT_TRUE(seen.count({scene, accel, rays})) << scene << " " << accel << " " << rays;
  EXPECT_EQ(seen.size(), json["cells"].size());
  std::string md = read_text(dir.file("out/bench.md"));
  EXPECT_NE(md.find("| tetra:levels=2 | grid |"), std::string::npos) << md;
}

// --diffuse-sort always: the diffuse cells of structures whose scattered
// calls can sort (single-ray kernels on a CPU device) are sorted in every
// launch, agree with brute force and say so; no other cell is. never: none
// is. Anything else: one message naming the option.
TEST(CliBench, DiffuseSortAlwaysSortsOnlyTheDiffuseCellsThatCan) {
  for (const char* policy : {"always", "never"}) {
    SCOPED_TRACE(policy);
    TempDir dir;
    CliRun run = run_cli(dir,
                         {"bench", "--size", "32", "--scene", "bunny", "--accel", "bvh,bvh-packet,grid", "--rays",
                          "primary,diffuse", "--repeat", "2", "--check-rays", "64", "--device", "0", "--diffuse-sort",
                          policy, "-o", dir.file("out")},
                         scenes_env());
    ASSERT_EQ(run.status, 0) << run.err;
    nlohmann::json json = nlohmann::json::parse(read_text(dir.file("out/bench.json")));
    EXPECT_EQ(json["options"]["diffuse_sort"], policy);
    const bool cpu = json["devices"][0]["type"] == "cpu";
    ASSERT_EQ(json["cells"].size(), 6u);
    for (const auto& cell : json["cells"]) {
      const bool sorts = std::string(policy) == "always" && cpu && cell["rays"] == "diffuse" &&
                         cell["accel"] != "bvh-packet";
      EXPECT_EQ(cell["sorted"].get<bool>(), sorts) << cell.dump();
      EXPECT_EQ(cell["sorted_runs"].get<int>(), sorts ? 2 : 0) << cell.dump();
      EXPECT_TRUE(cell["check"]["ok"].get<bool>()) << cell.dump();
    }
    std::string md = read_text(dir.file("out/bench.md"));
    if (cpu) EXPECT_EQ(md.find(" sorted ") != std::string::npos, std::string(policy) == "always") << md;
  }
  TempDir dir;
  CliRun bad = run_cli(dir, {"bench", "--size", "32", "--diffuse-sort", "sometimes", "-o", dir.file("out")},
                       scenes_env());
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.err.find("--diffuse-sort sometimes: unknown sort policy (known: measured, always, never)"),
            std::string::npos)
      << bad.err;
}

// --precision sets every structure's level and --embree-robust Embree's
// watertight mode; both are recorded with the run and its cells.
TEST(CliBench, PrecisionAndEmbreeFlagsAreRecorded) {
  TempDir dir;
  CliRun run = run_cli(dir,
                       {"bench", "--size", "16", "--scene", "bunny", "--accel", "bvh", "--rays", "primary,shadow",
                        "--repeat", "1", "--check-rays", "32", "--device", "0", "--precision", "fast",
                        "--embree-robust", "-o", dir.file("out")},
                       scenes_env());
  ASSERT_EQ(run.status, 0) << run.err;
  nlohmann::json json = nlohmann::json::parse(read_text(dir.file("out/bench.json")));
  EXPECT_EQ(json["options"]["precision"], "fast");
  EXPECT_EQ(json["options"]["embree_flags"], "robust");
  ASSERT_EQ(json["cells"].size(), 2u);
  for (const auto& cell : json["cells"]) {
    EXPECT_EQ(cell["precision"], "fast");
    EXPECT_TRUE(cell["check"]["ok"].get<bool>()) << cell.dump();
  }
#ifdef RTCL_TESTS_EXPECT_EMBREE
  ASSERT_TRUE(json["embree"].is_object());
  EXPECT_EQ(json["embree"]["flags"], "robust");
  for (const auto& b : json["embree"]["baselines"]) EXPECT_TRUE(b["check"]["ok"].get<bool>()) << b.dump();
  for (const auto& cell : json["cells"]) EXPECT_GT(cell["embree"]["ratio"].get<double>(), 0.0) << cell.dump();
#endif
  EXPECT_NE(read_text(dir.file("out/bench.md")).find("precision fast"), std::string::npos);
}

// --instances adds the instanced-scene section: rtcl's top-level commits and
// traces, and Embree's, with the same instance and triangle on (nearly)
// every ray.
TEST(CliBench, InstancesSectionComparesTheScenes) {
  TempDir dir;
  CliRun run = run_cli(dir,
                       {"bench", "--size", "16", "--scene", "tetra:levels=1", "--accel", "bvh", "--rays", "primary",
                        "--repeat", "2", "--check-rays", "8", "--device", "0", "--instances", "50", "-o",
                        dir.file("out")},
                       scenes_env());
  ASSERT_EQ(run.status, 0) << run.err;
  nlohmann::json json = nlohmann::json::parse(read_text(dir.file("out/bench.json")));
  ASSERT_EQ(json["instances"].size(), 1u) << json.dump();
  const nlohmann::json& section = json["instances"][0];
  EXPECT_EQ(section["mesh"], "bunny");
  EXPECT_EQ(section["instances"], 50);
  EXPECT_EQ(section["rays"], 256);
  EXPECT_EQ(section["commit_ms_runs"].size(), 2u);
  EXPECT_EQ(section["trace_ms_runs"].size(), 2u);
  EXPECT_GT(section["device_bytes"].get<double>(), 0.0);
#ifdef RTCL_TESTS_EXPECT_EMBREE
  ASSERT_TRUE(section["embree"].is_object()) << section.dump();
  EXPECT_EQ(section["embree"]["commit_ms_runs"].size(), 2u);
  EXPECT_EQ(section["embree"]["trace_ms_runs"].size(), 2u);
  EXPECT_GE(section["embree"]["agreeing"].get<double>(), 0.95 * 256) << section.dump();
#endif
  EXPECT_NE(read_text(dir.file("out/bench.md")).find("### 50 instances of bunny"), std::string::npos);
}

// Each bad input: a non-zero exit and one "rtcl: error:" line naming it,
// nothing written.
TEST(CliBench, BadInputIsOneMessageBeforeDeviceWork) {
  TempDir dir;
  dir.write("blocker", "a file, not a directory");
  struct Case {
    std::vector<std::string> args;
    std::string fragment;
  };
  std::vector<Case> cases = {
      {{"--accel", "bvh,octree-x"}, "octree-x"},
      {{"--scene", "bunny,cube"}, "unknown scene 'cube'"},
      {{"--scene", "tetra:levels=99"}, "levels must be an integer in [0, 11]"},
      {{"--scene", "soup:size=5"}, "count=N"},
      {{"--rays", "primary,caustic"}, "unknown ray set 'caustic'"},
      {{"--repeat", "0"}, "--repeat"},
      {{"--precision", "medium"}, "--precision medium: unknown precision level"},
      {{"--instances", "-3"}, "--instances"},
      {{"-o", dir.file("blocker") + "/out"}, "cannot create the directory"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = {"bench", "--size", "8"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    if (c.args[0] != "-o") args.insert(args.end(), {"-o", dir.file("out")});
    CliRun run = run_cli(dir, args, scenes_env());
    EXPECT_NE(run.status, 0) << c.fragment;
    EXPECT_EQ(count_of(run.err, "rtcl: error:"), 1u) << run.err;
    EXPECT_NE(run.err.find(c.fragment), std::string::npos) << run.err;
    EXPECT_EQ(run.err.find("rtcl bench: ["), std::string::npos) << "device work started: " << run.err;
  }
  CliRun missing = run_cli(dir, {"bench", "--scene", "dragon", "--scenes-dir", dir.path(), "-o", dir.file("out")});
  EXPECT_NE(missing.status, 0);
  EXPECT_NE(missing.err.find("stanford_dragon_100k/dragon.obj not found"), std::string::npos) << missing.err;
}

}  // namespace
}  // namespace rtcl::test
