// The image-level speed/accuracy trade, every knob on two scenes: time and
// error (display RMSE and SSIM, rtcl/render/image_metrics.hpp) against a
// converged image of the same renderer (1024 spp, Sobol, another seed),
// rendered once outside the timed region.
//
//   trade/<scene>/ray/<sampler>/spp:<n>[/light:<k>][/gaussian][/depth:<d>][/min-weight:<w>]
//   trade/<scene>/selective/spp:<n>/t:<threshold>[/block:<b>]
//   trade/<scene>/wavelet/spp:<n>/budget:<fraction>[/block:<b>]
//
// Scenes: scenes/cornell_soft.json (the lamp's emissive triangles as area
// lights, a glossy and a glass sphere, a thin lens) and scenes/sibenik.json
// with its point light made a sphere light of radius 1 (soft shadows) and a
// red ball of radius 0.8 moving 2 units across the nave over the shutter
// (motion blur).
// Size $RTCL_BENCH_TRADE_RES squared (default 128); Sobol, depth 5, 1 light
// sample, box filter, min weight 0.001, block 8 unless named. Each iteration renders another
// seed; counters: rmse and ssim (root mean square and mean over the
// iterations), frame_ms (mean wall clock of a frame), traced (share of the
// pixels traced). bench/plot_trade.py makes the tables and plots.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>

#include "bench_scenes.hpp"
#include "rtcl/render/image_metrics.hpp"
#include "rtcl/render/renderer.hpp"
#include "rtcl/render/selective.hpp"
#include "rtcl/render/wavelet.hpp"
#include "rtcl/scene/scene_file.hpp"

namespace rtcl::bench {
namespace {

std::uint32_t trade_size() {
  const char* value = std::getenv("RTCL_BENCH_TRADE_RES");
  if (!value || !*value) return 128;
  long n = std::strtol(value, nullptr, 10);
  return n >= 16 && n <= 4096 ? static_cast<std::uint32_t>(n) : 128;
}

SceneDescription trade_scene(const std::string& name) {
  if (name == "cornell") return load_scene(repo_scene("cornell_soft.json"));
  SceneDescription scene = load_scene(repo_scene("sibenik.json"));
  scene.lights.at(0).shape = LightShape::sphere;
  scene.lights.at(0).radius = 1.0f;
  // A ball crossing the nave during the shutter: motion blur.
  Material red;
  red.name = "moving ball";
  red.diffuse = red.ambient = {0.8f, 0.15f, 0.1f};
  scene.materials.push_back(red);
  SceneSphere ball = SceneSphere::still({-9.0, -10.0, -1.0}, 0.8, static_cast<std::uint32_t>(scene.materials.size() - 1));
  ball.moving = true;
  ball.end_center = ball.center + glm::dvec3(0.0, 0.0, 2.0);
  ball.end_radius = ball.radius;
  ball.motion_key = "trade_bench: moving ball";
  scene.spheres.push_back(ball);
  return scene;
}

enum class Method { ray, selective, wavelet };

struct Knobs {
  Method method = Method::ray;
  Sampler sampler = Sampler::sobol;
  Filter filter = Filter::box;
  std::uint32_t spp = 1, light_samples = 1, depth = 5, block = 8;
  float threshold = 0.05f, budget = 0.25f, min_weight = 1e-3f;
};

RenderSettings settings(const Knobs& k, std::uint32_t seed) {
  RenderSettings s;
  s.width = s.height = trade_size();
  s.spp = k.spp;
  s.sampler = k.sampler;
  s.filter = k.filter;
  s.light_samples = k.light_samples;
  s.max_depth = k.depth;
  s.min_weight = k.min_weight;
  s.seed = seed;
  return s;
}

struct TradeFixture {
  std::unique_ptr<Renderer> renderer;
  Image converged;
};

TradeFixture& fixture(const std::string& scene) {
  static std::map<std::string, TradeFixture> fixtures;
  auto it = fixtures.find(scene);
  if (it != fixtures.end()) return it->second;
  TradeFixture f;
  f.renderer = std::make_unique<Renderer>(bench_device(), trade_scene(scene), "bvh");
  Knobs converged;
  converged.spp = 1024;
  f.converged = f.renderer->render(settings(converged, 7777));
  return fixtures.emplace(scene, std::move(f)).first->second;
}

// One frame; *traced: the share of pixels traced.
Image frame(TradeFixture& f, const Knobs& k, std::uint32_t seed, double* traced) {
  const RenderSettings s = settings(k, seed);
  SelectiveStats stats;
  *traced = 1.0;
  if (k.method == Method::ray) return f.renderer->render(s);
  Image image;
  if (k.method == Method::selective) {
    SelectiveSettings sel;
    sel.block = k.block;
    sel.threshold = k.threshold;
    image = render_selective(*f.renderer, s, sel, &stats);
  } else {
    image = render_wavelet(*f.renderer, s, WaveletSettings{k.block, k.budget}, &stats);
  }
  *traced = double(stats.traced_pixels) / (double(s.width) * s.height);
  return image;
}

void trade_benchmark(benchmark::State& state, std::string scene, Knobs k) {
  try {
    TradeFixture& f = fixture(scene);
    double traced = 0.0;
    frame(f, k, 0, &traced);  // warm-up
    double sq = 0.0, ssim = 0.0, ms = 0.0;
    std::uint32_t seed = 1;
    for (auto _ : state) {
      auto start = std::chrono::steady_clock::now();
      Image image = frame(f, k, seed++, &traced);
      const double frame_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      state.SetIterationTime(frame_ms * 1e-3);
      ms += frame_ms;
      const double rmse = display_rmse(image, f.converged);
      sq += rmse * rmse;
      ssim += display_ssim(image, f.converged);
    }
    const double n = double(std::max<benchmark::IterationCount>(1, state.iterations()));
    state.counters["rmse"] = std::sqrt(sq / n);
    state.counters["ssim"] = ssim / n;
    state.counters["frame_ms"] = ms / n;
    state.counters["traced"] = traced;
    state.SetLabel(bench_device().info().name);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

std::string trim(float v) {
  std::string s = std::to_string(v);
  s.erase(s.find_last_not_of('0') + 1);
  if (s.back() == '.') s.pop_back();
  return s;
}

void add(const std::string& scene, const Knobs& k, const std::string& tail) {
  std::string name = "trade/" + scene + "/" + tail;
  benchmark::RegisterBenchmark(name.c_str(), trade_benchmark, scene, k)
      ->UseManualTime()
      ->Iterations(2)
      ->Unit(benchmark::kMillisecond);
}

[[maybe_unused]] const bool trade_registered = [] {
  for (const std::string scene : {"cornell", "sibenik"}) {
    for (Sampler sampler : {Sampler::random, Sampler::stratified, Sampler::sobol})
      for (std::uint32_t spp : {1u, 4u, 16u, 64u}) {
        Knobs k;
        k.sampler = sampler;
        k.spp = spp;
        add(scene, k, "ray/" + std::string(sampler_name(sampler)) + "/spp:" + std::to_string(spp));
      }
    Knobs k;
    k.spp = 32;
    add(scene, k, "ray/sobol/spp:32");
    k.spp = 128;
    add(scene, k, "ray/sobol/spp:128");
    k.spp = 8;
    add(scene, k, "ray/sobol/spp:8");
    for (std::uint32_t light : {4u, 16u}) {
      Knobs l;
      l.spp = 4;
      l.light_samples = light;
      add(scene, l, "ray/sobol/spp:4/light:" + std::to_string(light));
    }
    Knobs g;
    g.spp = 16;
    g.filter = Filter::gaussian;
    add(scene, g, "ray/sobol/spp:16/gaussian");
    for (std::uint32_t depth : {1u, 2u, 3u}) {
      Knobs d;
      d.spp = 16;
      d.depth = depth;
      add(scene, d, "ray/sobol/spp:16/depth:" + std::to_string(depth));
    }
    for (float w : {0.0f, 0.05f, 0.2f}) {
      Knobs m;
      m.spp = 16;
      m.min_weight = w;
      add(scene, m, "ray/sobol/spp:16/min-weight:" + trim(w));
    }
    for (std::uint32_t spp : {4u, 16u, 64u})
      for (float t : {0.05f, 0.1f, 0.2f, 0.4f}) {
        Knobs s;
        s.method = Method::selective;
        s.spp = spp;
        s.threshold = t;
        add(scene, s, "selective/spp:" + std::to_string(spp) + "/t:" + trim(t));
      }
    for (std::uint32_t block : {4u, 16u}) {
      Knobs s;
      s.method = Method::selective;
      s.spp = 16;
      s.block = block;
      add(scene, s, "selective/spp:16/t:0.05/block:" + std::to_string(block));
    }
    for (std::uint32_t spp : {4u, 16u, 64u})
      for (float b : {0.15f, 0.3f, 0.5f}) {
        Knobs w;
        w.method = Method::wavelet;
        w.spp = spp;
        w.budget = b;
        add(scene, w, "wavelet/spp:" + std::to_string(spp) + "/budget:" + trim(b));
      }
  }
  return true;
}();

}  // namespace
}  // namespace rtcl::bench
