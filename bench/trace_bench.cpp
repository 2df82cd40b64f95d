// rtcl's structures on the OpenCL device:
//   build/<scene>/<accel>          host build + flatten time (stats().build_ms)
//   trace/<scene>/<kind>/<accel>   kernel time of one launch over the ray set; kinds:
//     primary, shadow, diffuse (pixel order) and primary-tiled, shadow-morton,
//     diffuse-morton (the same rays reordered for packets)
//   sweep/<scene>/<kind>/grid/<option>=<value>   the same for the grid built
//     with that option (lambda=..., res=AxBxC, macro=...): the lecture's
//     trade-off of cell count against list length, and the macrocell size
//     (bench/plot_sweep.py plots it)
//   sweep/<scene>/<kind>/kdtree/<options>, sweep/<scene>/<kind>/bsp/<option>=<value>
//     the kd-tree's SAH costs, empty-space bonus and exact build; the BSP's
//     depth and leaf size
// Kernel time comes from OpenCL event profiling (COMMAND_START .. COMMAND_END)
// and is reported as manual time; a warm-up launch first absorbs PoCL's
// compile-on-first-launch. Brute force traces a subset (brute_ray_limit()).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>

#include "bench/support/timing.hpp"
#include "bench_scenes.hpp"
#include "rtcl/accel.hpp"

namespace rtcl::bench {
namespace {

// Device-side state for the resident scene: built structures and uploaded
// ray sets, released when a benchmark for another scene starts.
class DeviceScene {
 public:
  struct Rays {
    const RaySet* host = nullptr;  // what was uploaded: the scene's set or `subset`
    RaySet subset;
    cl::Buffer rays, hits;
  };

  static DeviceScene& get(const std::shared_ptr<const BenchScene>& scene) {
    static std::unique_ptr<DeviceScene> resident;
    if (!resident || resident->scene_ != scene) {
      resident.reset();
      resident.reset(new DeviceScene(scene));
    }
    return *resident;
  }

  const Accel& accel(const std::string& name) {
    auto& slot = accels_[name];
    if (!slot) slot = make_accel(bench_device(), name, scene_->geometry);
    return *slot;
  }

  // Once per structure and ray set (not per repetition): a launch of the same
  // size as the timed ones, since PoCL generates code at the first launch of
  // each work-group size, checked against the reference so that a wrong
  // structure cannot look fast. Returns agreement() of that launch.
  double warm_up(const std::string& spec, const Accel& accel, RayKind kind, const Rays& rays) {
    auto key = std::make_pair(spec, kind);
    if (auto it = agreement_.find(key); it != agreement_.end()) return it->second;
    std::size_t count = rays.host->rays.size();
    Query query = ray_kind_query(kind);
    accel.trace(query, rays.rays, rays.hits, count).wait();
    std::vector<Hit> hits(count);
    bench_device().queue().enqueueReadBuffer(rays.hits, CL_TRUE, 0, count * sizeof(Hit), hits.data());
    return agreement_[key] = agreement(hits, *rays.host, query);
  }

  // The ray set for `kind`, limited to `limit` rays (0: all).
  const Rays& rays(RayKind kind, std::size_t limit) {
    auto key = std::make_pair(kind, limit);
    if (auto it = rays_.find(key); it != rays_.end() && it->second.hits() != nullptr) return it->second;
    Rays& r = rays_[key];  // filled in place: host may point at r.subset
    if (limit) {
      r.subset = subset(scene_->rays(kind), limit);
      r.host = &r.subset;
    } else {
      r.host = &scene_->rays(kind);
    }
    const Device& device = bench_device();
    std::size_t count = r.host->rays.size();
    r.rays = device.upload(r.host->rays.data(), count * sizeof(Ray), "benchmark rays");
    r.hits = device.allocate(count * sizeof(Hit), "benchmark hits");
    return r;
  }

 private:
  explicit DeviceScene(std::shared_ptr<const BenchScene> scene) : scene_(std::move(scene)) {}
  std::shared_ptr<const BenchScene> scene_;
  std::map<std::string, std::unique_ptr<Accel>> accels_;
  std::map<std::pair<RayKind, std::size_t>, Rays> rays_;
  std::map<std::pair<std::string, RayKind>, double> agreement_;
};


double bytes_per_triangle(const AccelStats& stats, std::size_t triangles) {
  return triangles ? static_cast<double>(stats.device_bytes) / static_cast<double>(triangles) : 0.0;
}

void trace_benchmark(benchmark::State& state, const std::string& scene_name, RayKind kind,
                     const std::string& accel_name) {
  try {
    auto scene = bench_scene(scene_name);
    DeviceScene& device_scene = DeviceScene::get(scene);
    const Accel& accel = device_scene.accel(accel_name);
    std::size_t limit = accel_name == "brute"                 ? brute_ray_limit()
                        : accel_name.rfind("grid", 0) == 0 ? scene->spec->grid_ray_limit
                                                           : 0;
    const DeviceScene::Rays& rays = device_scene.rays(kind, limit);
    std::size_t count = rays.host->rays.size();
    Query query = ray_kind_query(kind);

    double agree = device_scene.warm_up(accel_name, accel, kind, rays);

    for (auto _ : state) {
      cl::Event done = accel.trace(query, rays.rays, rays.hits, count);
      done.wait();
      state.SetIterationTime(kernel_seconds(done));
    }
    state.counters["rays"] = benchmark::Counter(static_cast<double>(count), benchmark::Counter::kIsIterationInvariantRate);
    state.counters["ray_count"] = static_cast<double>(count);
    state.counters["hit_fraction"] = rays.host->hit_fraction();
    state.counters["agree"] = agree;
    state.counters["bytes_per_tri"] = bytes_per_triangle(accel.stats(), scene->triangle_count());
    state.counters["build_ms"] = accel.stats().build_ms;
    state.counters["device_bytes"] = static_cast<double>(accel.stats().device_bytes);
    state.counters["cells"] = static_cast<double>(accel.stats().node_count);
    state.SetLabel(accel.device().info().name);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

void build_benchmark(benchmark::State& state, const std::string& scene_name, const std::string& accel_name) {
  try {
    auto scene = bench_scene(scene_name);
    const Device& device = bench_device();
    static std::set<std::string> compiled;  // the first make_accel also builds the trace program
    if (compiled.insert(accel_name).second) make_accel(device, accel_name, scene->geometry);
    AccelStats stats;
    double total_ms = 0.0;
    for (auto _ : state) {
      auto accel = make_accel(device, accel_name, scene->geometry);
      stats = accel->stats();
      total_ms += stats.build_ms;
      state.SetIterationTime(stats.build_ms * 1e-3);
    }
    state.counters["build_ms"] = total_ms / static_cast<double>(std::max<benchmark::IterationCount>(1, state.iterations()));
    state.counters["bytes_per_tri"] = bytes_per_triangle(stats, scene->triangle_count());
    state.counters["triangles"] = static_cast<double>(scene->triangle_count());
    state.counters["nodes"] = static_cast<double>(stats.node_count);
    state.counters["leaves"] = static_cast<double>(stats.leaf_count);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

[[maybe_unused]] const bool trace_registered = add_scene_hook([](const SceneSpec& spec) {
  const std::vector<std::string> names = accel_names();
  for (const std::string& accel : names)
    benchmark::RegisterBenchmark(("build/" + spec.name + "/" + accel).c_str(), build_benchmark, spec.name, accel)
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond);
  std::vector<RayKind> kinds(std::begin(ray_kinds), std::end(ray_kinds));
  kinds.insert(kinds.end(), std::begin(ordered_ray_kinds), std::end(ordered_ray_kinds));
  for (RayKind kind : kinds)
    for (const std::string& accel : names)
      benchmark::RegisterBenchmark(
          ("trace/" + spec.name + "/" + ray_kind_name(kind) + "/" + accel).c_str(), trace_benchmark, spec.name,
          kind, accel)
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond);
});

// The grid's density sweep: lambda from 1/8 to 64 cells per primitive, and
// cubic resolutions, on the ray kinds below; the BVH of the same run is
// trace/<scene>/<kind>/bvh.
[[maybe_unused]] const bool sweep_registered = add_scene_hook([](const SceneSpec& spec) {
  if (spec.name == "dragon") return;
  const char* lambdas[] = {"0.125", "0.25", "0.5", "1", "2", "4", "8", "16", "32", "64"};
  const char* cubes[] = {"16x16x16", "32x32x32", "64x64x64", "128x128x128", "256x256x256"};
  std::vector<std::string> options;
  for (const char* l : lambdas) options.push_back(std::string("lambda=") + l);
  for (const char* r : cubes) options.push_back(std::string("res=") + r);
  for (const char* m : {"1", "2", "8", "16"}) options.push_back(std::string("macro=") + m);
  for (RayKind kind : {RayKind::primary, RayKind::diffuse})
    for (const std::string& option : options)
      benchmark::RegisterBenchmark(
          ("sweep/" + spec.name + "/" + ray_kind_name(kind) + "/grid/" + option).c_str(), trace_benchmark,
          spec.name, kind, "grid:" + option)
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond);
});

// The mixed-volume BVH with its filters forced (docs/structures.md): one
// kind at cost 0 (wherever it cuts a child's box) and the others off, and
// all at cost 0 (each node takes the kind that cuts most); the plain BVH
// and bvh-mixed at its measured costs of the same run are
// trace/<scene>/<kind>/bvh and .../bvh-mixed.
[[maybe_unused]] const bool mixed_sweep_registered = add_scene_hook([](const SceneSpec& spec) {
  for (RayKind kind : ray_kinds)
    for (const char* costs : {"sphere_cost=0,kdop_cost=64,obb_cost=64", "sphere_cost=64,kdop_cost=0,obb_cost=64",
                              "sphere_cost=64,kdop_cost=64,obb_cost=0", "sphere_cost=0,kdop_cost=0,obb_cost=0"})
      benchmark::RegisterBenchmark(
          ("sweep/" + spec.name + "/" + ray_kind_name(kind) + "/bvh-mixed/" + costs).c_str(), trace_benchmark,
          spec.name, kind, std::string("bvh-mixed:") + costs)
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond);
});

// The kd-tree's SAH traversal cost (intersection cost 20; the default
// batch = 4, ct = 30) per batch, the empty-space bonus, and the exact
// sweep below 64 references and throughout (Wald & Havran's build) against
// the binned default; and the BSP's depth and leaf size; on the ray kinds
// below (docs/structures.md).
[[maybe_unused]] const bool kd_sweep_registered = add_scene_hook([](const SceneSpec& spec) {
  if (spec.name == "dragon") return;
  std::vector<std::string> specs;
  for (const char* ct : {"ct=10", "ct=20", "ct=40", "ct=60", "batch=8,ct=15", "batch=8,ct=30", "batch=2,ct=40",
                         "batch=1,ct=30", "batch=1,ct=60", "batch=1,ct=120", "empty=0", "empty=0.5", "exact=64",
                         "exact=1073741824"})
    specs.push_back(std::string("kdtree:") + ct);
  for (const char* o : {"depth=14", "depth=18", "depth=22", "depth=26", "leaf=2", "leaf=12"}) specs.push_back(std::string("bsp:") + o);
  for (RayKind kind : {RayKind::primary, RayKind::shadow, RayKind::diffuse})
    for (const std::string& accel : specs) {
      std::string name = accel;
      name[name.find(':')] = '/';
      benchmark::RegisterBenchmark(("sweep/" + spec.name + "/" + ray_kind_name(kind) + "/" + name).c_str(),
                                   trace_benchmark, spec.name, kind, accel)
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond);
    }
});

}  // namespace
}  // namespace rtcl::bench
