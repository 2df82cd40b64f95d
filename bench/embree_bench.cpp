// Embree 3, the yardstick, over the same scenes and ray sets:
//   build/<scene>/embree, build/<scene>/embree-high   rtcCommitScene wall time
//   embree/<scene>/<kind>, embree/<scene>/<kind>/high  rtcIntersect1 / rtcOccluded1
//   embree/<scene>/<kind>/packet                       rtcIntersect8 / rtcOccluded8 over the
//                                                      8-ray groups rtcl's packet kernels take
// Traversal runs on host_threads() threads (wall time of the whole set,
// manual time, the traversal alone: Embree's ray records are built before
// and the answers read after the timed region, as rtcl's kernel time leaves
// out upload and read-back); builds use Embree's TBB tasking with the same
// thread count.
#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>
#include <string>

#include "bench_scenes.hpp"
#include "bench/support/embree_baseline.hpp"

namespace rtcl::bench {
namespace {

// Embree scenes for the resident benchmark scene, one per build quality.
const EmbreeScene& embree_scene(const std::shared_ptr<const BenchScene>& scene, EmbreeQuality quality) {
  static std::shared_ptr<const BenchScene> owner;
  static std::unique_ptr<EmbreeScene> built[2];
  if (owner != scene) {
    for (auto& b : built) b.reset();
    owner = scene;
  }
  auto& slot = built[quality == EmbreeQuality::high ? 1 : 0];
  if (!slot) slot = std::make_unique<EmbreeScene>(scene->geometry, quality, host_threads());
  return *slot;
}

double bytes_per_triangle(std::size_t bytes, std::size_t triangles) {
  return triangles ? static_cast<double>(bytes) / static_cast<double>(triangles) : 0.0;
}

void embree_trace_benchmark(benchmark::State& state, const std::string& scene_name, RayKind kind, EmbreeQuality quality,
                     EmbreeApi api) {
  try {
    auto scene = bench_scene(scene_name);
    const EmbreeScene& embree = embree_scene(scene, quality);
    const RaySet& rays = scene->rays(kind);
    std::size_t count = rays.rays.size();
    Query query = ray_kind_query(kind);
    unsigned threads = host_threads();
    std::vector<Hit> hits(count);
    embree.trace(query, rays.rays.data(), hits.data(), count, threads, api);  // warm-up (page-in, TBB start)
    double agree = agreement(hits, rays, query);
    for (auto _ : state) {
      embree.prepare(query, rays.rays.data(), count, api);  // untimed: Embree's records built before the loop
      auto start = std::chrono::steady_clock::now();
      embree.trace_prepared(threads);
      state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    embree.answers(hits.data());
    agree = std::min(agree, agreement(hits, rays, query));
    state.counters["rays"] = benchmark::Counter(static_cast<double>(count), benchmark::Counter::kIsIterationInvariantRate);
    state.counters["ray_count"] = static_cast<double>(count);
    state.counters["hit_fraction"] = rays.hit_fraction();
    state.counters["agree"] = agree;
    state.counters["bytes_per_tri"] = bytes_per_triangle(embree.bytes(), scene->triangle_count());
    state.counters["build_ms"] = embree.build_ms();
    state.counters["threads"] = threads;
    state.SetLabel("Embree " + embree_version(threads) + " " + embree_api_name(api, query));
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

void embree_build_benchmark(benchmark::State& state, const std::string& scene_name, EmbreeQuality quality) {
  try {
    auto scene = bench_scene(scene_name);
    std::size_t bytes = 0;
    double total_ms = 0.0;
    for (auto _ : state) {
      EmbreeScene embree(scene->geometry, quality, host_threads());
      bytes = embree.bytes();
      total_ms += embree.build_ms();
      state.SetIterationTime(embree.build_ms() * 1e-3);
    }
    state.counters["build_ms"] = total_ms / static_cast<double>(state.iterations() ? state.iterations() : 1);
    state.counters["bytes_per_tri"] = bytes_per_triangle(bytes, scene->triangle_count());
    state.counters["triangles"] = static_cast<double>(scene->triangle_count());
    state.counters["threads"] = host_threads();
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

[[maybe_unused]] const bool embree_registered = add_scene_hook([](const SceneSpec& spec) {
  for (EmbreeQuality quality : {EmbreeQuality::standard, EmbreeQuality::high}) {
    std::string name = "build/" + spec.name + "/embree" + (quality == EmbreeQuality::high ? "-high" : "");
    benchmark::RegisterBenchmark(name.c_str(), embree_build_benchmark, spec.name, quality)
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond);
  }
  for (RayKind kind : ray_kinds)
    for (EmbreeQuality quality : {EmbreeQuality::standard, EmbreeQuality::high}) {
      std::string name = "embree/" + spec.name + "/" + ray_kind_name(kind);
      if (quality == EmbreeQuality::high) name += "/high";
      benchmark::RegisterBenchmark(name.c_str(), embree_trace_benchmark, spec.name, kind, quality, EmbreeApi::single)
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond);
    }
  if (embree_has_packet8(host_threads()))
    for (RayKind kind : ray_kinds) {
      std::string name = "embree/" + spec.name + "/" + ray_kind_name(kind) + "/packet";
      benchmark::RegisterBenchmark(name.c_str(), embree_trace_benchmark, spec.name, kind, EmbreeQuality::standard,
                                   EmbreeApi::packet8)
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond);
    }
});

}  // namespace
}  // namespace rtcl::bench
