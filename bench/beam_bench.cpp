// Beam tracing against the ray tracer: the speed/accuracy trade on the
// Cornell box of scenes/cornell_mirror_beam.json (a mirror tall block and a
// mirror right wall, point light, polygons only; built here from the mesh).
//   beam/cornell_mirror/<exact|key>   rtcl render --method beam (depth 5)
//   ray/cornell_mirror/spp:<n>        the ray tracer, n = 1, 4, 16, 64 (depth 5, stratified)
// Time: wall clock of one frame (manual time); counters: beams, fragments
// and pixel pieces (beam), rays (ray), and rmse: RMSE of the display values
// (channels clamped to [0, 1] as the PNG shows them; the lamp's radiance,
// 17, would otherwise dominate) against the ray tracer at
// $RTCL_BENCH_BEAM_REF_SPP (default 1024) spp, rendered once outside the
// timed region. Size $RTCL_BENCH_BEAM_RES squared (default 256). With
// $RTCL_BENCH_BEAM_IMAGES set to a directory, each configuration's image is
// written there as <name>.png (README, "Beam tracing").
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>

#include "bench_scenes.hpp"
#include "rtcl/beam/beam_renderer.hpp"
#include "rtcl/render/image_metrics.hpp"
#include "rtcl/render/renderer.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "rtcl/scene/scene_file.hpp"

namespace rtcl::bench {
namespace {

std::uint32_t env_number(const char* name, std::uint32_t fallback, long lo, long hi) {
  const char* value = std::getenv(name);
  if (!value || !*value) return fallback;
  long n = std::strtol(value, nullptr, 10);
  return n >= lo && n <= hi ? static_cast<std::uint32_t>(n) : fallback;
}
std::uint32_t image_size() { return env_number("RTCL_BENCH_BEAM_RES", 256, 8, 4096); }

Scene cornell_mirror() {
  LoadedMesh mesh = load_mesh(scenes_dir() + "/cornell_box/CornellBox-Original.obj");
  Scene scene;
  scene.source = "cornell_box (mirrors)";
  scene.camera.position = {0.0f, 1.0f, 3.9f};
  scene.camera.look_at = {0.0f, 1.0f, 0.0f};
  scene.camera.fov_deg = 39.3f;
  scene.ambient = glm::vec3(0.1f);
  scene.lights.push_back(PointLight{glm::vec3(0.0f, 1.9f, -0.03f), glm::vec3(1.0f, 0.85f, 0.7f), 1.2f});
  for (const MeshMaterial& m : mesh.materials) scene.materials.push_back(material_from_mtl(m));
  for (Material& m : scene.materials) {
    if (m.name == "shortBox") m.diffuse = {0.725f, 0.71f, 0.68f};
    if (m.name == "tallBox") {
      m.diffuse = glm::vec3(0.02f);
      m.specular = glm::vec3(0.5f);
      m.shininess = 200.0f;
      m.kr = glm::vec3(0.85f);
    }
    if (m.name == "rightWall") {
      m.diffuse = {0.03f, 0.1f, 0.03f};
      m.specular = glm::vec3(0.0f);
      m.kr = {0.6f, 0.75f, 0.6f};
    }
  }
  SceneMesh sm;
  sm.name = "cornell_box";
  sm.vertices = std::move(mesh.geometry.vertices);
  sm.triangles = std::move(mesh.geometry.triangles);
  sm.materials = std::move(mesh.triangle_material);
  scene.meshes.push_back(std::move(sm));
  return scene;
}

struct Fixture {
  Scene scene = cornell_mirror();
  std::unique_ptr<Renderer> renderer;
  Image reference;
};

Fixture& fixture() {
  static Fixture f = [] {
    Fixture x;
    x.renderer = std::make_unique<Renderer>(bench_device(), x.scene, "bvh");
    RenderSettings s;
    s.width = s.height = image_size();
    s.spp = env_number("RTCL_BENCH_BEAM_REF_SPP", 1024, 1, 65536);
    s.seed = 7;  // not the seed of the measured renders
    x.reference = x.renderer->render(s);
    return x;
  }();
  return f;
}

void maybe_write(const std::string& name, const Image& image) {
  const char* dir = std::getenv("RTCL_BENCH_BEAM_IMAGES");
  if (dir && *dir) write_image(std::string(dir) + "/" + name + ".png", image);
}

void beam_benchmark(benchmark::State& state, beam::DepthOrder order, const std::string& name) {
  try {
    Fixture& f = fixture();
    beam::BeamSettings s;
    s.width = s.height = image_size();
    s.order = order;
    Image image = beam::render_beam(bench_device(), f.scene, s);  // warm-up: kernel builds
    beam::BeamStats st;
    for (auto _ : state) {
      image = beam::render_beam(bench_device(), f.scene, s, &st);
      state.SetIterationTime(st.render_ms * 1e-3);
    }
    state.counters["frame_ms"] = st.render_ms;
    state.counters["clip_ms"] = st.clip_ms;
    state.counters["tile_beams"] = double(st.tiles);
    state.counters["reflected_beams"] = double(st.reflected_beams);
    state.counters["levels"] = st.levels;
    state.counters["fragments"] = double(st.fragments);
    state.counters["pixel_pieces"] = double(st.pixel_pieces);
    state.counters["shadow_rays"] = double(st.shadow_rays);
    state.counters["rmse"] = display_rmse(image, f.reference);
    maybe_write(name, image);
    state.SetLabel(bench_device().info().name);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

void ray_benchmark(benchmark::State& state, std::uint32_t spp, const std::string& name) {
  try {
    Fixture& f = fixture();
    RenderSettings s;
    s.width = s.height = image_size();
    s.spp = spp;
    Image image = f.renderer->render(s);  // warm-up
    for (auto _ : state) {
      image = f.renderer->render(s);
      state.SetIterationTime(f.renderer->stats().render_ms * 1e-3);
    }
    state.counters["frame_ms"] = f.renderer->stats().render_ms;
    state.counters["rays"] = double(f.renderer->stats().rays.total());
    state.counters["rmse"] = display_rmse(image, f.reference);
    maybe_write(name, image);
    state.SetLabel(bench_device().info().name);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

[[maybe_unused]] const bool registered = [] {
  for (auto [order, name] : {std::pair{beam::DepthOrder::exact, "exact"}, std::pair{beam::DepthOrder::key, "key"}})
    benchmark::RegisterBenchmark((std::string("beam/cornell_mirror/") + name).c_str(), beam_benchmark, order,
                                 std::string("beam-") + name)
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond);
  for (std::uint32_t spp : {1u, 4u, 16u, 64u})
    benchmark::RegisterBenchmark(("ray/cornell_mirror/spp:" + std::to_string(spp)).c_str(), ray_benchmark, spp,
                                 "ray-spp" + std::to_string(spp))
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond);
  return true;
}();

}  // namespace
}  // namespace rtcl::bench
