// The speed/accuracy trade of the precision levels (src/rtcl/precision.hpp):
//   precision/<scene>/<level>/<accel>    primary rays of a bench scene: Mrays/s (kernel time of one
//                                        launch) and, on every k-th ray (at most $RTCL_BENCH_PRECISION_RAYS,
//                                        default 2048), the errors against the double-precision reference
//   precision/closed/<mesh>/<level>/<accel>  rays from inside closed meshes aimed exactly at every
//                                        vertex and edge midpoint: leaks (a miss is a ray through the mesh)
//   precision/render/<case>/<level>      the default scene at a scale: image RMSE against the double-precision
//                                        host reference renderer, and self-hits of spawned rays
// Counters (JSON): wrong_prim, false_hit, missed_hit (fractions of the subset the reference decides), t_ulps_mean,
// t_ulps_max (where the primitive agrees), leaks; rmse, smooth_pixels_off, self_hits.
// The references are independent of the code under test: tests/support/reference.cpp (double-precision brute
// force) and tests/support/reference_renderer.cpp (double-precision recursive renderer).
#include <benchmark/benchmark.h>

#include <glm/gtc/matrix_transform.hpp>

#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench/support/timing.hpp"
#include "bench_scenes.hpp"
#include "ray_sets.hpp"
#include "rtcl/accel.hpp"
#include "rtcl/render/renderer.hpp"
#include "rtcl/scene/default_scene.hpp"
#include "support/closed_meshes.hpp"
#include "support/reference.hpp"
#include "support/reference_renderer.hpp"

namespace rtcl::bench {
namespace {

std::size_t precision_ray_limit() {
  const char* v = std::getenv("RTCL_BENCH_PRECISION_RAYS");
  return v && *v ? static_cast<std::size_t>(std::strtoull(v, nullptr, 10)) : 2048;
}


std::vector<Hit> trace_all(const Accel& accel, const std::vector<Ray>& rays, Query query) {
  const Device& device = accel.device();
  std::vector<Hit> hits(rays.size());
  if (rays.empty()) return hits;
  cl::Buffer r = device.upload(rays.data(), rays.size() * sizeof(Ray), "precision rays");
  cl::Buffer h = device.allocate(rays.size() * sizeof(Hit), "precision hits");
  accel.trace(query, r, h, rays.size()).wait();
  device.queue().enqueueReadBuffer(h, CL_TRUE, 0, hits.size() * sizeof(Hit), hits.data());
  return hits;
}

// |a - b| in units of the float spacing at b.
double ulps(float a, float b) {
  double spacing = std::nextafter(std::abs(b), INFINITY) - std::abs(b);
  return std::abs(static_cast<double>(a) - b) / spacing;
}

struct Errors {
  double wrong_prim = 0, false_hit = 0, missed_hit = 0, t_ulps_mean = 0, t_ulps_max = 0;
};

// Against reference_closest (the nearest hit that is clear by 256 float ulps
// of the scene); rays the reference calls ambiguous count as decided when
// judge() accepts the device's answer.
Errors closest_errors(const Geometry& g, const std::vector<Ray>& rays, const std::vector<Hit>& hits,
                      const std::vector<Hit>& reference) {
  Errors e;
  std::size_t t_count = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Hit& d = hits[i];
    const Hit& r = reference[i];
    if (d.prim == r.prim) {
      if (d.prim >= 0) {
        double u = ulps(d.t, r.t);
        e.t_ulps_mean += u;
        e.t_ulps_max = std::max(e.t_ulps_max, u);
        ++t_count;
      }
      continue;
    }
    if (test::judge(g, rays[i], d, Query::closest).empty()) continue;  // within tolerance: either answer
    if (d.prim < 0) e.missed_hit += 1;
    else if (r.prim < 0) e.false_hit += 1;
    else e.wrong_prim += 1;
  }
  double n = static_cast<double>(std::max<std::size_t>(1, rays.size()));
  e.wrong_prim /= n;
  e.false_hit /= n;
  e.missed_hit /= n;
  if (t_count) e.t_ulps_mean /= static_cast<double>(t_count);
  return e;
}

// At most `limit` rays spread over the whole image: an odd stride, so that
// the picks do not line up in the columns of a power-of-two wide image.
RaySet scattered_subset(const std::vector<Ray>& rays, std::size_t limit) {
  std::size_t stride = std::max<std::size_t>(1, (rays.size() + limit - 1) / limit) | 1;
  RaySet out;
  for (std::size_t i = 0; i < rays.size(); i += stride) out.rays.push_back(rays[i]);
  return out;
}

// One scene's structures per level, its primary rays on the device and the
// reference of the subset: built at the first benchmark of the scene.
struct PrecisionScene {
  std::shared_ptr<const BenchScene> scene;
  RaySet subset;
  std::vector<Hit> reference;
  cl::Buffer rays, hits;
  std::map<std::string, std::unique_ptr<Accel>> accels;
};

PrecisionScene& precision_scene(const std::string& name) {
  static std::unique_ptr<PrecisionScene> resident;
  if (!resident || resident->scene->spec->name != name) {
    resident.reset();
    auto p = std::make_unique<PrecisionScene>();
    p->scene = bench_scene(name);
    p->subset = scattered_subset(p->scene->primary.rays, precision_ray_limit());
    p->reference = test::reference_closest_all(p->scene->geometry, p->subset.rays);
    const std::vector<Ray>& all = p->scene->primary.rays;
    p->rays = bench_device().upload(all.data(), all.size() * sizeof(Ray), "primary rays");
    p->hits = bench_device().allocate(all.size() * sizeof(Hit), "primary hits");
    resident = std::move(p);
  }
  return *resident;
}

void scene_benchmark(benchmark::State& state, const std::string& scene_name, Precision level,
                     const std::string& accel_name) {
  try {
    PrecisionScene& p = precision_scene(scene_name);
    std::string key = std::string(precision_name(level)) + "/" + accel_name;
    auto& accel = p.accels[key];
    if (!accel) accel = make_accel(bench_device(), accel_name, p.scene->geometry, {level, {}});
    std::size_t count = p.scene->primary.rays.size();
    accel->trace(Query::closest, p.rays, p.hits, count).wait();  // warm-up: code generation
    for (auto _ : state) {
      cl::Event done = accel->trace(Query::closest, p.rays, p.hits, count);
      done.wait();
      state.SetIterationTime(kernel_seconds(done));
    }
    Errors e = closest_errors(p.scene->geometry, p.subset.rays, trace_all(*accel, p.subset.rays, Query::closest),
                              p.reference);
    state.counters["rays"] = benchmark::Counter(static_cast<double>(count), benchmark::Counter::kIsIterationInvariantRate);
    state.counters["wrong_prim"] = e.wrong_prim;
    state.counters["false_hit"] = e.false_hit;
    state.counters["missed_hit"] = e.missed_hit;
    state.counters["t_ulps_mean"] = e.t_ulps_mean;
    state.counters["t_ulps_max"] = e.t_ulps_max;
    state.counters["checked_rays"] = static_cast<double>(p.subset.rays.size());
  } catch (const std::exception& ex) {
    state.SkipWithError(ex.what());
  }
}

// Closed meshes and rays from inside at every vertex and edge midpoint.
struct ClosedCase {
  std::string name;
  Geometry mesh;
  std::vector<Ray> rays;
};

const std::vector<ClosedCase>& closed_cases() {
  static const std::vector<ClosedCase> cases = [] {
    std::vector<ClosedCase> out;
    auto add = [&](std::string name, Geometry mesh, std::vector<glm::vec3> origins) {
      ClosedCase c{std::move(name), std::move(mesh), {}};
      std::vector<glm::vec3> targets(c.mesh.vertices.begin(), c.mesh.vertices.end());
      for (auto [a, b] : test::unique_edges(c.mesh)) targets.push_back(0.5f * (c.mesh.vertices[a] + c.mesh.vertices[b]));
      for (glm::vec3 o : origins)
        for (glm::vec3 t : targets) {
          glm::vec3 d = t - o;
          c.rays.push_back({o.x, o.y, o.z, d.x, d.y, d.z, 0.0f, INFINITY});
        }
      out.push_back(std::move(c));
    };
    std::vector<glm::vec3> inside = {{0, 0, 0}, {0.1f, -0.2f, 0.15f}, {-0.3f, 0.05f, 0.2f}};
    add("icosphere4", test::icosphere(4), inside);
    add("cube8", test::cube_grid(8), inside);
    add("uvsphere", test::uv_sphere(48, 96), inside);
    Geometry far = test::icosphere(4);
    std::vector<glm::vec3> far_inside;
    for (auto& v : far.vertices) v = v * 1000.0f + glm::vec3(1e4f, -2e4f, 3e4f);
    for (glm::vec3 o : inside) far_inside.push_back(o * 1000.0f + glm::vec3(1e4f, -2e4f, 3e4f));
    add("icosphere4-far", far, far_inside);
    return out;
  }();
  return cases;
}

void closed_benchmark(benchmark::State& state, std::size_t index, Precision level, const std::string& accel_name) {
  try {
    const ClosedCase& c = closed_cases()[index];
    auto accel = make_accel(bench_device(), accel_name, c.mesh, {level, {}});
    std::vector<Hit> hits;
    for (auto _ : state) hits = trace_all(*accel, c.rays, Query::closest);
    std::size_t leaks = 0;
    for (const Hit& h : hits) leaks += h.prim < 0;
    state.counters["leaks"] = static_cast<double>(leaks);
    state.counters["leak_rate"] = static_cast<double>(leaks) / static_cast<double>(c.rays.size());
    state.counters["checked_rays"] = static_cast<double>(c.rays.size());
  } catch (const std::exception& ex) {
    state.SkipWithError(ex.what());
  }
}

// The default scene at a scale: image error against the reference renderer,
// and self-hits of mirror rays spawned from the camera hits by the renderer's
// offset rule of that level (kernels/render/shade.cl): a ray leaving a flat
// triangle can never meet that triangle again, so every such hit is a
// self-hit.
struct RenderCase {
  const char* name;
  glm::dmat4 transform;
};

const RenderCase render_cases[] = {
    {"scale-1", glm::dmat4(1.0)},
    {"scale-1e-4", glm::scale(glm::dmat4(1.0), glm::dvec3(1e-4))},
    {"scale-1e5", glm::scale(glm::dmat4(1.0), glm::dvec3(1e5))},
    {"translate-1e5", glm::translate(glm::dmat4(1.0), glm::dvec3(1e5, -1e5, 1e5))},
};

double self_hit_rate(const Geometry& g, const Accel& accel, const std::vector<Ray>& camera) {
  std::vector<Hit> hits = trace_all(accel, camera, Query::closest);
  std::vector<Ray> spawned;
  std::vector<int> from;
  for (std::size_t i = 0; i < camera.size(); ++i) {
    int prim = hits[i].prim;
    if (prim < 0 || prim >= static_cast<int>(g.triangles.size())) continue;
    glm::vec3 v0 = g.vertices[g.triangles[prim].x], e1 = g.vertices[g.triangles[prim].y] - v0,
              e2 = g.vertices[g.triangles[prim].z] - v0;
    glm::vec3 p = v0 + hits[i].u * e1 + hits[i].v * e2;
    float extent = std::max(glm::max(glm::abs(e1).x, glm::max(glm::abs(e1).y, glm::abs(e1).z)),
                            glm::max(glm::abs(e2).x, glm::max(glm::abs(e2).y, glm::abs(e2).z)));
    glm::vec3 n = glm::normalize(glm::cross(e1 / extent, e2 / extent));
    glm::vec3 d(camera[i].dx, camera[i].dy, camera[i].dz);
    if (glm::dot(n, d) > 0) n = -n;
    float point = std::max(std::abs(p.x), std::max(std::abs(p.y), std::abs(p.z)));
    float offset = accel.precision() == Precision::fast ? 1e-4f : FLT_EPSILON * (3.0f * point + 16.0f * extent);
    glm::vec3 o = p + offset * n, r = d - 2.0f * glm::dot(d, n) * n;
    spawned.push_back({o.x, o.y, o.z, r.x, r.y, r.z, 0.0f, INFINITY});
    from.push_back(prim);
  }
  std::vector<Hit> again = trace_all(accel, spawned, Query::closest);
  std::size_t self = 0;
  for (std::size_t i = 0; i < spawned.size(); ++i) self += again[i].prim == from[i];
  return spawned.empty() ? 0.0 : static_cast<double>(self) / static_cast<double>(spawned.size());
}

void precision_render_benchmark(benchmark::State& state, const RenderCase& c, Precision level) {
  try {
    SceneDescription scene = transform_scene(default_scene(), c.transform);
    RenderSettings settings;
    settings.width = settings.height = 96;
    static std::map<std::string, test::ReferenceImage> references;
    auto it = references.find(c.name);
    if (it == references.end()) it = references.emplace(c.name, test::reference_render(scene, settings)).first;
    const test::ReferenceImage& ref = it->second;
    Renderer renderer(bench_device(), scene, "bvh", {level, {}});
    Image image;
    for (auto _ : state) image = renderer.render(settings);
    std::vector<std::uint8_t> excused = test::edge_pixels(ref.image, 0.05, 1);
    for (std::size_t i = 0; i < excused.size(); ++i) excused[i] |= ref.ambiguous[i];
    test::ImageDifference d = test::compare_images(image, ref.image, excused);
    state.counters["rmse"] = d.rmse;
    state.counters["smooth_pixels_off"] = static_cast<double>(d.pixels_over_unmasked);
    FlatScene flat = flatten(scene);
    std::vector<Ray> camera;
    bench::Camera bench_camera{glm::vec3(scene.camera.position), glm::vec3(scene.camera.look_at), glm::vec3(scene.camera.up),
                        scene.camera.fov_deg};
    camera = primary_rays(bench_camera, 256, 256);
    state.counters["self_hits"] = self_hit_rate(flat.geometry, renderer.accel(), camera);
  } catch (const std::exception& ex) {
    state.SkipWithError(ex.what());
  }
}

const Precision kLevels[] = {Precision::fast, Precision::robust, Precision::exact};

std::vector<std::string> traced_accels() {
  std::vector<std::string> names;
  for (const std::string& name : accel_names())
    if (name != "brute") names.push_back(name);  // O(rays x triangles): measured in trace/ on a subset only
  return names;
}

[[maybe_unused]] const bool registered_scenes = add_scene_hook([](const SceneSpec& spec) {
  for (Precision level : kLevels)
    for (const std::string& accel : traced_accels())
      benchmark::RegisterBenchmark(
          ("precision/" + spec.name + "/" + std::string(precision_name(level)) + "/" + accel).c_str(),
          scene_benchmark, spec.name, level, accel)
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond);
});

[[maybe_unused]] const bool registered_closed = [] {
  for (std::size_t i = 0; i < closed_cases().size(); ++i)
    for (Precision level : kLevels)
      for (const std::string& accel : traced_accels()) {
        benchmark::RegisterBenchmark(
            ("precision/closed/" + closed_cases()[i].name + "/" + std::string(precision_name(level)) + "/" + accel)
                .c_str(),
            closed_benchmark, i, level, accel)
            ->Iterations(1)
            ->Unit(benchmark::kMillisecond);
      }
  for (const RenderCase& c : render_cases)
    for (Precision level : kLevels)
      benchmark::RegisterBenchmark(
          ("precision/render/" + std::string(c.name) + "/" + std::string(precision_name(level))).c_str(),
          precision_render_benchmark, c, level)
          ->Iterations(1)
          ->Unit(benchmark::kMillisecond);
  return true;
}();

}  // namespace
}  // namespace rtcl::bench
