// What the mixed-volume BVH's builder chooses (src/rtcl/accel/
// bvh_volumes.hpp), per mesh and cost setting:
//   volume_choice/<scene>/<costs>   host time of choose_volume_filters over
//   the scene's binned-SAH BVH, with counters: nodes, slots (child slots),
//   records and lanes of each kind, and cost_ratio (expected cost with the
//   chosen filters / boxes alone; < 1 predicts fewer box-test units).
// <costs> is "default" (the measured VolumeCosts) or a filter kind free
// (cost 0) with the others off, or all free ("all=0").
#include <benchmark/benchmark.h>

#include <chrono>

#include "bench_scenes.hpp"
#include "rtcl/accel/bvh.hpp"
#include "rtcl/accel/bvh_volumes.hpp"
#include "rtcl/scene/mesh_io.hpp"

namespace rtcl::bench {
namespace {

struct CostSetting {
  const char* name;
  VolumeCosts costs;
};

const CostSetting cost_settings[] = {
    {"default", VolumeCosts{}},
    {"sphere=0", {0.0f, 64.0f, 64.0f, VolumeCosts{}.block}},
    {"kdop=0", {64.0f, 0.0f, 64.0f, VolumeCosts{}.block}},
    {"obb=0", {64.0f, 64.0f, 0.0f, VolumeCosts{}.block}},
    {"all=0", {0.0f, 0.0f, 0.0f, VolumeCosts{}.block}},
};

void volume_choice(benchmark::State& state, const SceneSpec* spec, const CostSetting* setting) {
  try {
    Geometry g = load_mesh(scenes_dir() + "/" + spec->file).geometry;
    Bvh8 bvh = flatten_bvh8(build_binary_bvh(g), g);
    std::size_t slots = 0;
    for (const Bvh8Node& n : bvh.nodes)
      for (rtcl_i32 c : n.child) slots += c != RTCL_CHILD_EMPTY;
    for (auto _ : state) {
      auto start = std::chrono::steady_clock::now();
      BvhVolumeFilters f = choose_volume_filters(bvh, setting->costs, g.source);
      state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      state.counters["nodes"] = static_cast<double>(bvh.nodes.size());
      state.counters["slots"] = static_cast<double>(slots);
      state.counters["sphere_nodes"] = static_cast<double>(f.spheres.size());
      state.counters["kdop_nodes"] = static_cast<double>(f.kdops.size());
      state.counters["obb_nodes"] = static_cast<double>(f.obbs.size());
      state.counters["sphere_lanes"] = static_cast<double>(f.lanes[RTCL_FILTER_SPHERE]);
      state.counters["kdop_lanes"] = static_cast<double>(f.lanes[RTCL_FILTER_KDOP]);
      state.counters["obb_lanes"] = static_cast<double>(f.lanes[RTCL_FILTER_OBB]);
      state.counters["cost_ratio"] = f.chosen_cost / f.aabb_cost;
    }
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

[[maybe_unused]] const bool volume_choice_registered = [] {
  for (const SceneSpec& spec : scene_specs()) {
    if (spec.stadium > 0.0f) continue;
    for (const CostSetting& setting : cost_settings)
      benchmark::RegisterBenchmark(("volume_choice/" + spec.name + "/" + setting.name).c_str(), volume_choice, &spec,
                                   &setting)
          ->UseManualTime()
          ->Iterations(1)
          ->Unit(benchmark::kMillisecond);
  }
  return true;
}();

}  // namespace
}  // namespace rtcl::bench
