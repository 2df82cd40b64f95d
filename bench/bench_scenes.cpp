#include "bench_scenes.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <thread>

#include "ray_sets.hpp"
#include "rtcl/error.hpp"
#include "rtcl/scene/procedural.hpp"
#include "rtcl/render/ray_order.hpp"
#include "rtcl/scene/mesh_io.hpp"

#ifdef RTCL_HAVE_EMBREE
#include "bench/support/embree_baseline.hpp"
#endif

namespace rtcl::bench {

const char* ray_kind_name(RayKind kind) {
  switch (kind) {
    case RayKind::primary: return "primary";
    case RayKind::shadow: return "shadow";
    case RayKind::diffuse: return "diffuse";
    case RayKind::primary_tiled: return "primary-tiled";
    case RayKind::shadow_morton: return "shadow-morton";
    case RayKind::diffuse_morton: return "diffuse-morton";
  }
  return "?";
}

Query ray_kind_query(RayKind kind) {
  return kind == RayKind::shadow || kind == RayKind::shadow_morton ? Query::any : Query::closest;
}

namespace {

long env_number(const char* name, long fallback, long lowest) {
  const char* value = std::getenv(name);
  if (!value || !*value) return fallback;
  char* end = nullptr;
  long n = std::strtol(value, &end, 10);
  if (*end != '\0' || n < lowest)
    throw Error(std::string("$") + name + "=" + value + ": expected an integer >= " + std::to_string(lowest));
  return n;
}

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// Answers reference queries for one scene (see oracle_name()).
class Oracle {
 public:
  explicit Oracle(const Geometry& geometry) : name_(oracle_name()) {
#ifdef RTCL_HAVE_EMBREE
    embree_ = std::make_unique<EmbreeScene>(geometry, EmbreeQuality::standard, host_threads());
#else
    accel_ = make_accel(bench_device(), name_, geometry);
#endif
  }

  const std::string& name() const { return name_; }

  std::vector<Hit> trace(Query query, const std::vector<Ray>& rays) const {
    std::vector<Hit> hits(rays.size());
#ifdef RTCL_HAVE_EMBREE
    embree_->trace(query, rays.data(), hits.data(), rays.size(), host_threads());
#else
    const Device& device = bench_device();
    cl::Buffer ray_buffer = device.upload(rays.data(), rays.size() * sizeof(Ray), "reference rays");
    cl::Buffer hit_buffer = device.allocate(rays.size() * sizeof(Hit), "reference hits");
    cl::Event done = accel_->trace(query, ray_buffer, hit_buffer, rays.size());
    std::vector<cl::Event> wait{done};
    device.queue().enqueueReadBuffer(hit_buffer, CL_TRUE, 0, hits.size() * sizeof(Hit), hits.data(), &wait);
#endif
    return hits;
  }

 private:
  std::string name_;
#ifdef RTCL_HAVE_EMBREE
  std::unique_ptr<EmbreeScene> embree_;
#else
  std::unique_ptr<Accel> accel_;
#endif
};

std::shared_ptr<const BenchScene> load_bench_scene(const SceneSpec& spec) {
  auto scene = std::make_shared<BenchScene>();
  scene->spec = &spec;
  auto start = std::chrono::steady_clock::now();
  LoadedMesh mesh = load_mesh(scenes_dir() + "/" + spec.file);
  scene->geometry = std::move(mesh.geometry);
  if (spec.stadium > 0.0f) add_stadium(scene->geometry, spec.stadium);
  validate(scene->geometry);
  scene->load_ms = ms_since(start);

  start = std::chrono::steady_clock::now();
  scene->width = scene->height = image_size();
  Oracle oracle(scene->geometry);
  scene->oracle = oracle.name();
  scene->primary.rays = primary_rays(spec.camera, scene->width, scene->height);
  scene->primary.reference = oracle.trace(Query::closest, scene->primary.rays);
  SecondaryRays secondary = secondary_rays(scene->geometry, scene->primary.rays, scene->primary.reference, spec.light);
  scene->shadow.rays = std::move(secondary.shadow);
  scene->diffuse.rays = std::move(secondary.diffuse);
  scene->shadow.reference = oracle.trace(Query::any, scene->shadow.rays);
  scene->diffuse.reference = oracle.trace(Query::closest, scene->diffuse.rays);
  auto reorder = [](const RaySet& set, const std::vector<std::uint32_t>& order) {
    return RaySet{gather<Ray>(set.rays, order), gather<Hit>(set.reference, order)};
  };
  auto size = static_cast<std::uint32_t>(scene->width);
  scene->primary_tiled = reorder(scene->primary, tile_order(size, size));
  Aabb bounds = scene->geometry.bounds();
  scene->shadow_morton = reorder(scene->shadow, morton_order(scene->shadow.rays, bounds));
  scene->diffuse_morton = reorder(scene->diffuse, morton_order(scene->diffuse.rays, bounds));
  scene->rays_ms = ms_since(start);

  if (const char* dir = std::getenv("RTCL_BENCH_DUMP"); dir && *dir)
    write_preview(std::string(dir) + "/" + spec.name + ".ppm", *scene);
  return scene;
}

}  // namespace

std::string oracle_name() {
#ifdef RTCL_HAVE_EMBREE
  return "embree";
#else
  auto names = accel_names();
  return std::find(names.begin(), names.end(), "bvh") != names.end() ? "bvh" : "brute";
#endif
}

std::string repo_scene(const std::string& name) {
  return std::string(RTCL_BENCH_REPO_SCENES) + "/" + name;
}

int image_size() { return static_cast<int>(env_number("RTCL_BENCH_RES", 1024, 1)); }

std::size_t brute_ray_limit() { return static_cast<std::size_t>(env_number("RTCL_BENCH_BRUTE_RAYS", 16384, 1)); }

unsigned host_threads() {
  unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  return static_cast<unsigned>(env_number("RTCL_BENCH_THREADS", hardware, 1));
}

const Device& bench_device() {
  static const Device device = Device::open();
  return device;
}

double RaySet::hit_fraction() const {
  if (reference.empty()) return 0.0;
  auto hits = std::count_if(reference.begin(), reference.end(), [](const Hit& h) { return h.prim >= 0; });
  return static_cast<double>(hits) / static_cast<double>(reference.size());
}

const RaySet& BenchScene::rays(RayKind kind) const {
  switch (kind) {
    case RayKind::shadow: return shadow;
    case RayKind::diffuse: return diffuse;
    case RayKind::primary_tiled: return primary_tiled;
    case RayKind::shadow_morton: return shadow_morton;
    case RayKind::diffuse_morton: return diffuse_morton;
    default: return primary;
  }
}

std::shared_ptr<const BenchScene> bench_scene(const std::string& name) {
  static std::mutex mutex;
  static std::shared_ptr<const BenchScene> resident;
  std::lock_guard lock(mutex);
  if (resident && resident->spec->name == name) return resident;
  const auto& specs = scene_specs();
  auto spec = std::find_if(specs.begin(), specs.end(), [&](const SceneSpec& s) { return s.name == name && !s.fit; });
  if (spec == specs.end()) throw Error("benchmark scene '" + name + "' is not defined in scene_specs()");
  resident.reset();  // release the previous scene before loading the next
  resident = load_bench_scene(*spec);
  return resident;
}

RaySet subset(const RaySet& set, std::size_t limit) {
  std::size_t n = set.rays.size();
  std::size_t stride = limit == 0 ? n : std::max<std::size_t>(1, (n + limit - 1) / limit);
  RaySet out;
  for (std::size_t i = 0; i < n; i += stride) {
    out.rays.push_back(set.rays[i]);
    if (i < set.reference.size()) out.reference.push_back(set.reference[i]);
  }
  return out;
}

double agreement(const std::vector<Hit>& hits, const RaySet& set, Query query) {
  std::size_t n = std::min(hits.size(), set.reference.size());
  if (n == 0) return 0.0;
  std::size_t agree = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Hit &a = hits[i], &b = set.reference[i];
    bool hit_a = a.prim >= 0, hit_b = b.prim >= 0;
    if (hit_a != hit_b) continue;
    if (hit_a && query == Query::closest && a.prim != b.prim && std::abs(a.t - b.t) > 1e-3f * std::abs(b.t)) continue;
    ++agree;
  }
  return static_cast<double>(agree) / static_cast<double>(n);
}

namespace {
std::vector<SceneHook>& hooks() {
  static std::vector<SceneHook> list;
  return list;
}
}  // namespace

bool add_scene_hook(SceneHook hook) {
  hooks().push_back(std::move(hook));
  return true;
}

void register_scene_benchmarks() {
  // Only the scenes with placed cameras (scene_specs() lists fitted ones
  // too, for `rtcl bench`).
  for (const SceneSpec& spec : scene_specs())
    if (!spec.fit)
      for (const SceneHook& hook : hooks()) hook(spec);
}

}  // namespace rtcl::bench
