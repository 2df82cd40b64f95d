// rtcl_build_ab: rtcl's BVH build against Embree's default build, both on
// the same host threads (all of them, or AB_THREADS), alternating in one
// process, scene by scene.
//
//   rtcl_build_ab SCENES ROUNDS
//   e.g. rtcl_build_ab bunny,dragon,soup:1000000 7
//
// A scene is a bench/ scene name (the shared meshes, scene_catalog.hpp) or
// soup:N (random_triangle_soup(N)). rtcl's time is what `rtcl bench`
// reports as build_ms (make_bvh): validate, the binary SAH build and the
// flatten into 8-wide nodes and blocks; the upload is not in it. Embree's is
// EmbreeScene::build_ms: geometry setup and rtcCommitScene at
// RTC_BUILD_QUALITY_MEDIUM (its default). One warm-up round per scene, then
// ROUNDS rounds of one build each, the order rotated each round. Prints per scene
// the fastest and median ms of each and their ratios (rtcl / Embree: < 1
// means rtcl builds faster), then the medians of rtcl's phases (validate,
// the binary build, the flatten).
//
// Environment: RTCL_SCENES_DIR; AB_BVH: rtcl's builds as `--accel` specs of
// the bvh, separated by spaces (default "bvh"; e.g. "bvh bvh:presplit=16
// bvh:greedy_levels=1024"); with several, each is a version of rtcl's build
// of its own row, all in every round, the order rotated;
// AB_THREADS: the host threads of both builders (default every hardware
// thread; rtcl's validate always uses them all), e.g. 1 to compare the
// builders' serial work; AB_GAP_MS: the pause before each build (default
// 20): longer than rtcl's threads spin once out of work (1 ms; TBB's
// workers spin too), so that neither builder's idle threads run into the
// other's timed build, and each build starts with its threads asleep, as a
// program's one build does.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "rtcl/accel/bvh.hpp"
#include "rtcl/accel_options.hpp"
#include "rtcl/bench/embree_baseline.hpp"
#include "rtcl/bench/scene_catalog.hpp"
#include "rtcl/error.hpp"
#include "rtcl/geometry.hpp"
#include "rtcl/scene/procedural.hpp"

#include "../ab_support.hpp"

namespace {

using namespace rtcl;
using namespace rtcl::bench;

Geometry load_scene(const std::string& name, const std::string& scenes_dir) {
  if (name.rfind("soup:", 0) == 0) {
    char* end = nullptr;
    const unsigned long long count = std::strtoull(name.c_str() + 5, &end, 10);
    if (count == 0 || *end != '\0') throw Error("scene '" + name + "': soup:N needs a positive triangle count");
    return random_triangle_soup(static_cast<std::size_t>(count));
  }
  const SceneSpec* spec = find_scene_spec(name);
  if (!spec) throw Error("scene '" + name + "': neither a bench/ scene nor soup:N");
  return spec_geometry(*spec, scenes_dir);
}

// ms of make_bvh's build_ms path without the upload: [0] the whole, then
// its phases: [1] validate, [2] the binary build (build_binary_bvh: the
// stored primitives, their boxes, the SAH build), [3] the flatten.
std::vector<double> rtcl_build_ms(const Geometry& geometry, const BvhConfig& config) {
  using Clock = std::chrono::steady_clock;
  auto ms = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
  const Clock::time_point start = Clock::now();
  validate(geometry, ZeroAreaTest::by_caller);
  const Clock::time_point validated = Clock::now();
  BuildTree tree = build_binary_bvh(geometry, config);
  const Clock::time_point built = Clock::now();
  Bvh8 bvh = flatten_bvh8(tree, geometry, flatten_options(config));
  const Clock::time_point flattened = Clock::now();
  if (bvh.nodes.empty()) throw Error("empty BVH");
  return {ms(start, flattened), ms(start, validated), ms(validated, built), ms(built, flattened)};
}

double embree_build_ms(const Geometry& geometry, unsigned threads) {
  return EmbreeScene(geometry, EmbreeQuality::standard, threads).build_ms();
}

std::string format_ms(double ms) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f", ms);
  return text;
}

int run(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: rtcl_build_ab SCENES ROUNDS  (e.g. bunny,soup:1000000 7)\n");
    return 2;
  }
  const std::vector<std::string> scenes = split(argv[1]);
  const int rounds = parse_rounds(argv[2]);
  const std::string scenes_dir = scenes_dir_or(RTCL_BUILD_AB_SCENES_DIR);
  const char* threads_env = std::getenv("AB_THREADS");
  unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  if (threads_env && *threads_env) {
    char* end = nullptr;
    const long value = std::strtol(threads_env, &end, 10);
    if (*end || value < 1 || value > 1024)
      throw Error(std::string("AB_THREADS: '") + threads_env + "' is not a count of 1..1024");
    threads = static_cast<unsigned>(value);
  }
  std::chrono::milliseconds gap{20};
  if (const char* gap_env = std::getenv("AB_GAP_MS"); gap_env && *gap_env) {
    char* end = nullptr;
    const long value = std::strtol(gap_env, &end, 10);
    if (*end || value < 0 || value > 10000) throw Error(std::string("AB_GAP_MS: '") + gap_env + "' is not 0..10000 ms");
    gap = std::chrono::milliseconds(value);
  }
  std::vector<BvhConfig> configs;  // AB_BVH's builds, SAH on `threads`
  std::vector<std::string> labels;
  const char* bvh_env = std::getenv("AB_BVH");
  std::istringstream specs(bvh_env && *bvh_env ? bvh_env : "bvh");
  for (std::string text; specs >> text;) {
    const AccelSpec spec = parse_accel_spec(text, "AB_BVH " + text);
    if (spec.name != "bvh") throw Error("AB_BVH " + text + ": not a spec of the bvh");
    AccelConfig accel_config;
    accel_config.options = spec.options;
    BvhConfig config = resolve_bvh_config(structure_spec(spec.name), accel_config);
    config.sah.thread_count = threads;
    configs.push_back(config);
    labels.push_back(text);
  }
  for (const std::string& name : scenes)
    if (name.rfind("soup:", 0) != 0 && !find_scene_spec(name))
      throw Error("scene '" + name + "': neither a bench/ scene nor soup:N");

  std::vector<std::string> phase_lines;
  std::printf("%u threads, Embree %s\n", threads, embree_version(threads).c_str());
  std::printf("| scene | triangles | rtcl ms (min / median) | Embree ms (min / median) | rtcl / Embree (min / median) |\n");
  std::printf("|---|--:|--:|--:|--:|\n");
  for (const std::string& name : scenes) {
    const Geometry geometry = load_scene(name, scenes_dir);
    for (const BvhConfig& config : configs) rtcl_build_ms(geometry, config);
    embree_build_ms(geometry, threads);
    std::vector<double> theirs;
    // phases[v][k]: version v's phase k (rtcl_build_ms), one entry per round
    std::vector<std::vector<std::vector<double>>> phases(configs.size(), std::vector<std::vector<double>>(4));
    const std::size_t versions = configs.size() + 1;  // the last one is Embree
    for (int round = 0; round < rounds; ++round)
      for (std::size_t j = 0; j < versions; ++j) {
        std::this_thread::sleep_for(gap);
        const std::size_t v = (j + static_cast<std::size_t>(round)) % versions;
        if (v == configs.size()) {
          theirs.push_back(embree_build_ms(geometry, threads));
          continue;
        }
        std::vector<double> p = rtcl_build_ms(geometry, configs[v]);
        for (std::size_t k = 0; k < p.size(); ++k) phases[v][k].push_back(p[k]);
      }
    for (std::size_t v = 0; v < configs.size(); ++v) {
      const std::vector<double>& ours = phases[v][0];
      std::string label = name;
      if (configs.size() > 1 || labels[v] != "bvh") label += " " + labels[v];
      std::printf("| %s | %zu | %.1f / %.1f | %.1f / %.1f | %.2f / %.2f |\n", label.c_str(),
                  geometry.triangles.size(), fastest(ours), median(ours), fastest(theirs), median(theirs),
                  fastest(ours) / fastest(theirs), median(ours) / median(theirs));
      phase_lines.push_back(label + ": validate " + format_ms(median(phases[v][1])) + ", binary build " +
                            format_ms(median(phases[v][2])) + ", flatten " + format_ms(median(phases[v][3])));
    }
    std::fflush(stdout);
  }
  std::printf("\nrtcl's phases (medians, ms):\n");
  for (const std::string& line : phase_lines) std::printf("  %s\n", line.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return run_main("rtcl_build_ab", run, argc, argv); }
