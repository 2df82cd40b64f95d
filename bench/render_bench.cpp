// The Whitted renderer, per scene and acceleration structure: frames per
// second and Mrays/s by ray kind (camera, shadow, secondary = reflection +
// refraction) at $RTCL_BENCH_RENDER_RES (default 512) squared, depth 5,
// 1 sample per pixel. Scenes: the built-in default scene, and sponza and
// sibenik with the camera and point light of scene_specs() and their MTL
// materials (sponza has none: loader grey); these have no mirror or glass,
// so "<scene>-kr25" gives every material kr = 0.25 to measure secondary
// rays on a large mesh (incoherent, to depth 4 at the default 1e-3 weight
// threshold).
//
// Per-kind Mrays/s are rays over the device time of that kind's trace
// kernels (event profiling); fps and Mrays/s (all kinds) use the wall clock
// of a whole frame: generation, tracing, shading, compaction, read-back.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <map>
#include <memory>
#include <string>

#include "bench_scenes.hpp"
#include "rtcl/render/renderer.hpp"
#include "rtcl/scene/default_scene.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "rtcl/scene/scene_file.hpp"

namespace rtcl::bench {
namespace {

std::uint32_t render_size() {
  const char* value = std::getenv("RTCL_BENCH_RENDER_RES");
  if (!value || !*value) return 512;
  long n = std::strtol(value, nullptr, 10);
  return n >= 1 && n <= 16384 ? static_cast<std::uint32_t>(n) : 512;
}

// A benchmark scene as the renderer sees it: the mesh with its MTL
// materials, the spec's camera and light.
SceneDescription render_scene(const SceneSpec& spec, float kr) {
  LoadedMesh mesh = load_mesh(scenes_dir() + "/" + spec.file);
  SceneDescription scene;
  scene.source = spec.name;
  scene.camera.position = spec.camera.eye;
  scene.camera.look_at = spec.camera.target;
  scene.camera.up = spec.camera.up;
  scene.camera.fov_deg = spec.camera.fov_y_deg;
  scene.ambient = glm::vec3(0.15f);
  scene.lights.push_back(PointLight{spec.light, glm::vec3(1.0f), 1.0f});
  for (const MeshMaterial& m : mesh.materials) {
    scene.materials.push_back(material_from_mtl(m));
    scene.materials.back().kr = glm::max(scene.materials.back().kr, glm::vec3(kr));
  }
  SceneMesh sm;
  sm.name = spec.file;
  rtcl::MeshShape& shape = sm.edit_shape();
  shape.vertices = std::move(mesh.geometry.vertices);
  shape.triangles = std::move(mesh.geometry.triangles);
  shape.materials = std::move(mesh.triangle_material);
  scene.meshes.push_back(std::move(sm));
  return scene;
}

// One renderer resident at a time (scene + structure); built outside timing.
Renderer& renderer_for(const std::string& scene_name, const std::string& accel, const SceneDescription* scene) {
  static std::string key;
  static std::unique_ptr<Renderer> renderer;
  if (key != scene_name + "/" + accel) {
    renderer.reset();
    renderer = std::make_unique<Renderer>(bench_device(), *scene, accel);
    key = scene_name + "/" + accel;
  }
  return *renderer;
}

double mrays(std::uint64_t rays, double ms) { return ms > 0.0 ? static_cast<double>(rays) / (ms * 1e3) : 0.0; }

void render_benchmark(benchmark::State& state, const std::string& scene_name, const SceneSpec* spec, float kr,
                      const std::string& accel) {
  try {
    static std::map<std::string, SceneDescription> scenes;  // small: meshes are flattened by each Renderer
    if (!scenes.count(scene_name)) {
      scenes.clear();
      scenes.emplace(scene_name, spec ? render_scene(*spec, kr) : default_scene());
    }
    Renderer& renderer = renderer_for(scene_name, accel, &scenes.at(scene_name));
    RenderSettings settings;
    settings.width = settings.height = render_size();
    settings.max_depth = 5;
    renderer.render(settings);  // warm-up: the device compiles each kernel at its first launch
    RenderStats total;
    for (auto _ : state) {
      renderer.render(settings);
      const RenderStats& s = renderer.stats();
      state.SetIterationTime(s.render_ms * 1e-3);
      total.render_ms += s.render_ms;
      total.camera_trace_ms += s.camera_trace_ms;
      total.shadow_trace_ms += s.shadow_trace_ms;
      total.secondary_trace_ms += s.secondary_trace_ms;
      total.shade_ms += s.shade_ms;
      total.compact_ms += s.compact_ms;
      total.rays.camera += s.rays.camera;
      total.rays.shadow += s.rays.shadow;
      total.rays.reflection += s.rays.reflection;
      total.rays.refraction += s.rays.refraction;
    }
    const double frames = static_cast<double>(std::max<benchmark::IterationCount>(1, state.iterations()));
    const RayCounts& r = total.rays;
    state.counters["fps"] = total.render_ms > 0.0 ? frames * 1e3 / total.render_ms : 0.0;
    state.counters["Mrays/s"] = mrays(r.total(), total.render_ms);
    state.counters["camera_Mrays/s"] = mrays(r.camera, total.camera_trace_ms);
    state.counters["shadow_Mrays/s"] = mrays(r.shadow, total.shadow_trace_ms);
    state.counters["secondary_Mrays/s"] = mrays(r.reflection + r.refraction, total.secondary_trace_ms);
    state.counters["rays/frame"] = static_cast<double>(r.total()) / frames;
    state.counters["secondary/frame"] = static_cast<double>(r.reflection + r.refraction) / frames;
    state.counters["shade_ms"] = total.shade_ms / frames;
    state.counters["compact_ms"] = total.compact_ms / frames;
    state.SetLabel(bench_device().info().name);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

// Brute force is O(rays x triangles): only on the small default scene.
void register_render(const std::string& scene_name, const SceneSpec* spec, float kr = 0.0f) {
  for (const std::string& accel : accel_names()) {
    if (spec && accel == "brute") continue;
    benchmark::RegisterBenchmark(("render/" + scene_name + "/" + accel).c_str(), render_benchmark, scene_name, spec,
                                 kr, accel)
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond);
  }
}

[[maybe_unused]] const bool registered_default = [] {
  register_render("default", nullptr);
  return true;
}();

[[maybe_unused]] const bool registered_meshes = add_scene_hook([](const SceneSpec& spec) {
  if (spec.name != "sponza" && spec.name != "sibenik") return;
  register_render(spec.name, &spec);
  register_render(spec.name + "-kr25", &spec, 0.25f);
});

}  // namespace
}  // namespace rtcl::bench
