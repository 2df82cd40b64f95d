// The distributed ray tracer's speed/accuracy trade on the Cornell box lit
// by its own lamp (emissive triangles as area lights), with a glossy sphere,
// a glass sphere and a thin lens: time against error for spp 1, 4, 16, 32, 64
// per sampler. Error: RMSE of the display values (each channel clamped to
// [0, 1], as the PNG shows them; the lamp's radiance, 17, would otherwise
// dominate) against a converged image of the same renderer (1024 spp, Sobol,
// another seed), rendered once outside the timed region. Size
// $RTCL_BENCH_DIST_RES squared (default 96); depth 5; 1 light sample per
// pixel sample, and ".../spp:<n>/light:<k>": k light samples (shadow rays
// instead of whole paths, for the soft shadows only).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>

#include "bench_scenes.hpp"
#include "rtcl/render/image_metrics.hpp"
#include "rtcl/render/renderer.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "rtcl/scene/scene_file.hpp"

namespace rtcl::bench {
namespace {

std::uint32_t image_size() {
  const char* value = std::getenv("RTCL_BENCH_DIST_RES");
  if (!value || !*value) return 96;
  long n = std::strtol(value, nullptr, 10);
  return n >= 8 && n <= 4096 ? static_cast<std::uint32_t>(n) : 96;
}

// scenes/cornell_soft.json, built here from the mesh.
SceneDescription cornell_soft() {
  LoadedMesh mesh = load_mesh(scenes_dir() + "/cornell_box/CornellBox-Original.obj");
  SceneDescription scene;
  scene.source = "cornell_box (soft)";
  scene.camera.position = {0.0f, 1.0f, 3.9f};
  scene.camera.look_at = {0.0f, 1.0f, 0.0f};
  scene.camera.fov_deg = 39.3f;
  scene.camera.aperture = 0.03f;
  scene.camera.focus_distance = 3.5f;
  scene.ambient = glm::vec3(0.1f);
  Light lamp;
  lamp.shape = LightShape::emissive;
  lamp.intensity = 0.08f;
  scene.lights.push_back(lamp);
  for (const MeshMaterial& m : mesh.materials) scene.materials.push_back(material_from_mtl(m));
  Material satin;
  satin.name = "satin";
  satin.diffuse = glm::vec3(0.02f);
  satin.specular = glm::vec3(0.5f);
  satin.shininess = 200.0f;
  satin.kr = glm::vec3(0.85f);
  satin.roughness = 0.15f;
  Material glass;
  glass.name = "glass";
  glass.diffuse = glm::vec3(0.0f);
  glass.specular = glm::vec3(0.6f);
  glass.shininess = 300.0f;
  glass.kt = glm::vec3(1.0f);
  const auto base = static_cast<std::uint32_t>(scene.materials.size());
  scene.materials.push_back(satin);
  scene.materials.push_back(glass);
  SceneMesh sm;
  sm.name = "CornellBox-Original.obj";
  rtcl::MeshShape& shape = sm.edit_shape();
  shape.vertices = std::move(mesh.geometry.vertices);
  shape.triangles = std::move(mesh.geometry.triangles);
  shape.materials = std::move(mesh.triangle_material);
  scene.meshes.push_back(std::move(sm));
  scene.spheres.push_back(SceneSphere::still({0.32, 0.8, 0.37}, 0.2, base));
  scene.spheres.push_back(SceneSphere::still({-0.45, 0.25, 0.55}, 0.25, base + 1));
  return scene;
}

RenderSettings settings(std::uint32_t spp, Sampler sampler, std::uint32_t seed, std::uint32_t light_samples = 1) {
  RenderSettings s;
  s.light_samples = light_samples;
  s.width = s.height = image_size();
  s.spp = spp;
  s.sampler = sampler;
  s.seed = seed;
  s.max_depth = 5;
  return s;
}

struct DistributedFixture {
  std::unique_ptr<Renderer> renderer;
  Image converged;
};

DistributedFixture& fixture() {
  static DistributedFixture f = [] {
    DistributedFixture x;
    x.renderer = std::make_unique<Renderer>(bench_device(), cornell_soft(), "bvh");
    x.converged = x.renderer->render(settings(1024, Sampler::sobol, 7777));
    return x;
  }();
  return f;
}

void distributed_benchmark(benchmark::State& state, Sampler sampler, std::uint32_t spp, std::uint32_t light_samples) {
  try {
    DistributedFixture& f = fixture();
    f.renderer->render(settings(spp, sampler, 0, light_samples));  // warm-up
    double sq = 0.0, ms = 0.0;
    std::uint32_t seed = 1;
    for (auto _ : state) {
      Image image = f.renderer->render(settings(spp, sampler, seed++, light_samples));  // another seed per iteration
      const double rmse = display_rmse(image, f.converged);
      state.SetIterationTime(f.renderer->stats().render_ms * 1e-3);
      sq += rmse * rmse;
      ms += f.renderer->stats().render_ms;
    }
    const double n = double(std::max<benchmark::IterationCount>(1, state.iterations()));
    state.counters["rmse"] = std::sqrt(sq / n);  // root of the mean square over the iterations' seeds
    state.counters["frame_ms"] = ms / n;
    state.SetLabel(bench_device().info().name);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

[[maybe_unused]] const bool distributed_registered = [] {
  struct Point {
    std::uint32_t spp, light_samples;
  };
  const Point points[] = {{1, 1}, {4, 1}, {16, 1}, {32, 1}, {64, 1}, {4, 4}, {4, 16}, {16, 4}};
  for (Sampler sampler : {Sampler::random, Sampler::stratified, Sampler::sobol})
    for (const Point& p : points) {
      std::string name = "distributed/cornell/" + std::string(sampler_name(sampler)) + "/spp:" + std::to_string(p.spp);
      if (p.light_samples > 1) name += "/light:" + std::to_string(p.light_samples);
      benchmark::RegisterBenchmark(name.c_str(), distributed_benchmark, sampler, p.spp, p.light_samples)
          ->UseManualTime()
          ->Iterations(4)
          ->Unit(benchmark::kMillisecond);
    }
  return true;
}();

}  // namespace
}  // namespace rtcl::bench
