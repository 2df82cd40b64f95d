// Beam tracing against the ray tracer: the speed/accuracy trade on
//   cornell_glass    scenes/cornell_glass_beam.json (a mirror tall block, a
//                    glass block of index 1.5, point light), size
//                    $RTCL_BENCH_BEAM_RES squared (default 256);
//   cornell_glass_ior1  the same with the glass of index 1, where the
//                    linearised M_t is exact (the identity): what the beam
//                    tracer's error through the glass is without the
//                    linearisation;
//   sibenik_mirror   scenes/sibenik_mirror_beam.json (75k triangles, a mirror
//                    floor), size $RTCL_BENCH_BEAM_SIBENIK_RES squared
//                    (default 128).
// Configurations (depth 5, BVH):
//   beam/<scene>            rtcl render --method beam (exact order, BVH cull)
//   beam/<scene>/cull:all   the same with every triangle tested exactly for
//                           the beams below the viewing beam (one iteration)
//   ray/<scene>/spp:<n>     the ray tracer, n = 1, 4, 16, 64 (stratified)
// Time: wall clock of one frame (manual time). Counters: beams, fragments,
// pixel pieces, cull_ms (host time of the candidates below the viewing beam)
// and clip_ms (beam); rays (ray); rmse: RMSE of the display values (channels
// clamped to [0, 1] as the PNG shows them) against the ray tracer at
// $RTCL_BENCH_BEAM_REF_SPP spp (default 1024; sibenik:
// $RTCL_BENCH_BEAM_SIBENIK_REF_SPP, default 1024), rendered once outside the
// timed region with another seed; rmse_glass (cornell_glass): the same over
// the pixels the glass block covers wholly (what is seen through it). With
// $RTCL_BENCH_BEAM_IMAGES set to a directory, each configuration's image and
// the reference are written there as <scene>-<name>.png (docs/rendering.md).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench_scenes.hpp"
#include "rtcl/beam/beam_renderer.hpp"
#include "rtcl/render/image_metrics.hpp"
#include "rtcl/render/renderer.hpp"
#include "rtcl/scene/scene_file.hpp"

namespace rtcl::bench {
namespace {

std::uint32_t env_number(const char* name, std::uint32_t fallback) {
  const char* value = std::getenv(name);
  if (!value || !*value) return fallback;
  long n = std::strtol(value, nullptr, 10);
  return n >= 1 && n <= 65536 ? static_cast<std::uint32_t>(n) : fallback;
}

struct BeamScene {
  const char* name;
  const char* file;
  float ior;  // > 0: every transmissive material's index of refraction replaced (1: M_t exact)
  const char* res_env;
  std::uint32_t res;
  const char* ref_env;
  std::uint32_t ref_spp;
  const char* glass;  // material whose covered pixels make rmse_glass, or nullptr
};
const BeamScene beam_scenes[] = {
    {"cornell_glass", "cornell_glass_beam.json", 0.0f, "RTCL_BENCH_BEAM_RES", 256, "RTCL_BENCH_BEAM_REF_SPP", 1024,
     "glass"},
    {"cornell_glass_ior1", "cornell_glass_beam.json", 1.0f, "RTCL_BENCH_BEAM_RES", 256, "RTCL_BENCH_BEAM_REF_SPP",
     1024, "glass"},
    {"sibenik_mirror", "sibenik_mirror_beam.json", 0.0f, "RTCL_BENCH_BEAM_SIBENIK_RES", 128,
     "RTCL_BENCH_BEAM_SIBENIK_REF_SPP", 1024, nullptr},
};

struct BeamFixture {
  SceneDescription scene;
  std::uint32_t size = 0;
  std::unique_ptr<Renderer> renderer;
  Image reference;
  std::vector<std::uint8_t> glass;  // per pixel: 1 where the glass covers it wholly
};

void maybe_write(const std::string& name, const Image& image) {
  const char* dir = std::getenv("RTCL_BENCH_BEAM_IMAGES");
  if (dir && *dir) write_image(std::string(dir) + "/" + name + ".png", image);
}

BeamFixture& fixture(const BeamScene& bs) {
  static std::map<std::string, std::unique_ptr<BeamFixture>> fixtures;
  if (auto it = fixtures.find(bs.name); it != fixtures.end()) return *it->second;
  auto f = std::make_unique<BeamFixture>();
  f->scene = load_scene(repo_scene(bs.file));
  if (bs.ior > 0.0f)
    for (Material& m : f->scene.materials)
      if (m.transmissive()) m.ior = bs.ior;
  f->size = env_number(bs.res_env, bs.res);
  f->renderer = std::make_unique<Renderer>(bench_device(), f->scene, "bvh");
  RenderSettings s;
  s.width = s.height = f->size;
  s.spp = env_number(bs.ref_env, bs.ref_spp);
  s.seed = 7;  // not the seed of the measured renders
  f->reference = f->renderer->render(s);
  maybe_write(std::string(bs.name) + "-reference", f->reference);
  if (bs.glass) {
    beam::BeamSettings b;
    b.width = b.height = f->size;
    FlatScene flat = flatten(f->scene);
    std::vector<double> covered(std::size_t(f->size) * f->size, 0.0);
    for (const beam::CoverageEntry& e : beam::beam_coverage(bench_device(), f->scene, b))
      if (f->scene.materials[flat.material[e.prim]].name == bs.glass) covered[e.pixel] += e.area;
    for (double a : covered) f->glass.push_back(a > 1.0 - 1e-6);
  }
  return *(fixtures[bs.name] = std::move(f));
}

// Display RMSE over the pixels marked in `mask`.
double masked_rmse(const Image& a, const Image& b, const std::vector<std::uint8_t>& mask) {
  double sum = 0.0;
  std::size_t n = 0;
  auto display = [](float c) { return std::min(std::max(double(c), 0.0), 1.0); };
  for (std::size_t p = 0; p < mask.size(); ++p)
    if (mask[p])
      for (int k = 0; k < 3; ++k, ++n) {
        double d = display(a.rgb[p * 3 + k]) - display(b.rgb[p * 3 + k]);
        sum += d * d;
      }
  return n ? std::sqrt(sum / double(n)) : 0.0;
}

void errors(benchmark::State& state, const BeamFixture& f, const Image& image) {
  state.counters["rmse"] = display_rmse(image, f.reference);
  if (!f.glass.empty()) state.counters["rmse_glass"] = masked_rmse(image, f.reference, f.glass);
}

void beam_benchmark(benchmark::State& state, const BeamScene* bs, beam::CandidateCull cull) {
  try {
    BeamFixture& f = fixture(*bs);
    beam::BeamSettings s;
    s.width = s.height = f.size;
    s.cull = cull;
    Image image = beam::render_beam(bench_device(), f.scene, s);  // warm-up: kernel builds
    beam::BeamStats st;
    for (auto _ : state) {
      image = beam::render_beam(bench_device(), f.scene, s, &st);
      state.SetIterationTime(st.render_ms * 1e-3);
    }
    state.counters["frame_ms"] = st.render_ms;
    state.counters["clip_ms"] = st.clip_ms;
    state.counters["cull_ms"] = st.cull_ms;
    state.counters["tile_beams"] = double(st.tiles);
    state.counters["reflected_beams"] = double(st.reflected_beams);
    state.counters["refracted_beams"] = double(st.refracted_beams);
    state.counters["total_internal"] = double(st.total_internal_reflections);
    state.counters["levels"] = st.levels;
    state.counters["candidates"] = double(st.candidates);
    state.counters["fragments"] = double(st.fragments);
    state.counters["pixel_pieces"] = double(st.pixel_pieces);
    state.counters["shadow_rays"] = double(st.shadow_rays);
    errors(state, f, image);
    if (cull == beam::CandidateCull::bvh) maybe_write(std::string(bs->name) + "-beam", image);
    state.SetLabel(bench_device().info().name);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

void ray_benchmark(benchmark::State& state, const BeamScene* bs, std::uint32_t spp) {
  try {
    BeamFixture& f = fixture(*bs);
    RenderSettings s;
    s.width = s.height = f.size;
    s.spp = spp;
    Image image = f.renderer->render(s);  // warm-up
    for (auto _ : state) {
      image = f.renderer->render(s);
      state.SetIterationTime(f.renderer->stats().render_ms * 1e-3);
    }
    state.counters["frame_ms"] = f.renderer->stats().render_ms;
    state.counters["rays"] = double(f.renderer->stats().rays.total());
    errors(state, f, image);
    maybe_write(std::string(bs->name) + "-ray-spp" + std::to_string(spp), image);
    state.SetLabel(bench_device().info().name);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

[[maybe_unused]] const bool beam_registered = [] {
  for (const BeamScene& bs : beam_scenes) {
    const std::string scene = bs.name;
    benchmark::RegisterBenchmark(("beam/" + scene).c_str(), beam_benchmark, &bs, beam::CandidateCull::bvh)
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("beam/" + scene + "/cull:all").c_str(), beam_benchmark, &bs,
                                 beam::CandidateCull::all)
        ->UseManualTime()
        ->Iterations(1)
        ->Unit(benchmark::kMillisecond);
    for (std::uint32_t spp : {1u, 4u, 16u, 64u})
      benchmark::RegisterBenchmark(("ray/" + scene + "/spp:" + std::to_string(spp)).c_str(), ray_benchmark, &bs, spp)
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond);
  }
  return true;
}();

}  // namespace
}  // namespace rtcl::bench
