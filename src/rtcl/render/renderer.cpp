#include "rtcl/render/renderer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "rtcl/error.hpp"
#include "rtcl/render/camera.hpp"
#include "rtcl/render/device_scene.hpp"
#include "rtcl/render/instanced_scene.hpp"
#include "rtcl/render/launch.hpp"
#include "rtcl/render/ray_queue.hpp"
#include "rtcl/render/render_layouts.hpp"
#include "rtcl/scene/motion.hpp"

namespace rtcl {

namespace {

const std::vector<cl::Event>* wait_list(const std::vector<cl::Event>& wait) { return wait.empty() ? nullptr : &wait; }

void store(float* out, const glm::dvec3& v) {
  out[0] = static_cast<float>(v.x);
  out[1] = static_cast<float>(v.y);
  out[2] = static_cast<float>(v.z);
}

double event_ms(const cl::Event& e) {
  auto start = e.getProfilingInfo<CL_PROFILING_COMMAND_START>();
  auto end = e.getProfilingInfo<CL_PROFILING_COMMAND_END>();
  return end > start ? static_cast<double>(end - start) * 1e-6 : 0.0;
}

void check_settings(const RenderSettings& s) {
  if (s.width == 0 || s.height == 0 || s.width > 65536 || s.height > 65536 ||
      std::uint64_t(s.width) * s.height > (1u << 28))
    throw Error("image size " + std::to_string(s.width) + "x" + std::to_string(s.height) +
                ": width and height must be 1 .. 65536 and the image at most 2^28 pixels");
  if (s.spp == 0 || s.spp > 65536) throw Error("spp " + std::to_string(s.spp) + ": must be 1 .. 65536");
  if (s.max_depth > 64) throw Error("depth " + std::to_string(s.max_depth) + ": must be 0 .. 64");
  if (!std::isfinite(s.min_weight) || s.min_weight < 0.0f)
    throw Error("min weight " + std::to_string(s.min_weight) + ": must be finite and not negative");
  if (s.batch_pixels == 0) throw Error("batch size must be positive");
  if (s.light_samples == 0 || s.light_samples > 4096)
    throw Error("light samples " + std::to_string(s.light_samples) + ": must be 1 .. 4096");
  if (std::uint64_t(s.spp) * s.light_samples > (1ull << 31))
    throw Error("spp times light samples must be at most 2^31");
  if (sampler_name(s.sampler) == "?") throw Error("unknown sampler (known: " + sampler_names() + ")");
  if (filter_name(s.filter) == "?") throw Error("unknown filter (known: " + filter_names() + ")");
}

// Shadow slots per shaded ray: one per point light, `light_samples` per area light.
std::uint32_t shadow_slots_per_ray(const SceneDescription& scene, std::uint32_t light_samples) {
  std::uint32_t slots = 0;
  for (const Light& l : scene.lights) slots += l.area() ? light_samples : 1u;
  return slots;
}

ImageRegion checked_region(const RenderSettings& s, const ImageRegion& r) {
  if (r.width == 0 && r.height == 0 && r.x0 == 0 && r.y0 == 0) return ImageRegion{0, 0, s.width, s.height};
  if (r.width == 0 || r.height == 0 || r.x0 >= s.width || r.y0 >= s.height || r.width > s.width - r.x0 ||
      r.height > s.height - r.y0)
    throw Error("image region " + std::to_string(r.width) + "x" + std::to_string(r.height) + " at (" +
                std::to_string(r.x0) + ", " + std::to_string(r.y0) + "): must be non-empty and inside the " +
                std::to_string(s.width) + "x" + std::to_string(s.height) + " image");
  return r;
}

}  // namespace

struct Renderer::State {
  Device device;
  SceneDescription scene;
  FlatScene flat;
  std::unique_ptr<Accel> accel;       // static scenes
  std::unique_ptr<MotionBvh> motion;  // moving scenes
  std::unique_ptr<InstancedScene> instanced;  // scenes that share mesh shapes (the two-level path)
  double build_ms = 0.0;                      // the two-level path's commits
  DeviceScene shading;
  cl::Kernel shade, accumulate;
  // Moving scenes: the ray-time kernels and the queue's and shadow queue's times.
  cl::Kernel queue_times, shadow_times;
  GrowingBuffer times{"ray times", sizeof(float)}, shadow_time{"shadow ray times", sizeof(float)};
  // The shade kernel for pixel lists (RTCL_PIXEL_SLOTS), built at the first
  // render_pixels; while `slots` is set, shade() uses it with `pixel_list`.
  cl::Kernel shade_slots;
  bool slots = false;
  cl::Buffer pixel_list;

  // Per render.
  RenderSettings settings;
  ImageRegion region;
  cl::Buffer camera, params, framebuffer, totals;
  // Per generation: queue -> hits -> radiance + slots -> next queue + shadow queue.
  RayQueue queue, next;
  GrowingBuffer hits{"hits", sizeof(Hit)}, radiance{"path radiance", RTCL_RADIANCE_BYTES};
  GrowingBuffer hit_objects{"hit objects", sizeof(cl_uint)};  // the two-level path: each hit's object
  std::vector<std::uint32_t> first_objects;  // render_pixels on the two-level path: the first hits' objects
  SpawnSlots spawn;
  ShadowSlots shadow_slots;
  ShadowQueue shadows;
  std::vector<cl::Event> last;  // what the next stage waits for
  std::uint32_t sample = 0;     // the pixel sample being traced
  std::uint32_t slots_per_ray = 0;  // shadow slots per shaded ray

  RenderStats stats;
  std::vector<cl::Event> camera_traces, secondary_traces, shadow_traces, generates, shades, accumulates;
  std::vector<std::pair<cl::Event, cl::Event>> compacts;  // first and last kernel of both compactions

  State(const Device& d, const SceneDescription& s) : device(d), scene(s), queue(d), next(d), shadows(d) {}
  // Whether rays carry times (moving objects on either path).
  bool timed() const { return motion || (instanced && instanced->moving()); }
};

Renderer::Renderer(const Device& device, const SceneDescription& scene, std::string_view accel_name, const AccelConfig& config,
                   MotionBounds motion_bounds)
    : s_(std::make_unique<State>(device, scene)) {
  if (shares_meshes(scene)) {
    auto start = std::chrono::steady_clock::now();
    s_->instanced = std::make_unique<InstancedScene>(device, scene, accel_name, config);
    s_->build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    s_->scene.lights = instanced_lights(scene);
    s_->shading = upload_instanced_scene(device, s_->scene, *s_->instanced);
  } else if (!scene_moves(scene)) {
    s_->flat = flatten(scene);
    s_->scene.lights = expand_emissive_lights(scene, s_->flat);
    s_->accel = make_accel(device, accel_name, s_->flat.geometry, config);
    s_->shading = upload_scene(device, s_->scene, s_->flat);
  } else {
    if (parse_accel_spec(accel_name).name != "bvh")
      throw Error("Renderer accel \"" + std::string(accel_name) + "\": " + scene.source +
                  " has moving objects, which only the motion BVH traces (accel bvh)");
    const double open = scene.camera.shutter_open, close = scene.camera.shutter_close;
    check_motion(scene, open, close);
    SceneDescription at_open = scene_at(scene, open), at_close = scene_at(scene, close);
    s_->flat = flatten(at_open);
    FlatScene end = flatten(at_close);
    s_->scene.lights = expand_emissive_lights(at_open, s_->flat);
    std::vector<Light> end_lights = expand_emissive_lights(at_close, end);
    for (std::size_t l = 0; l < end_lights.size(); ++l)
      if (end_lights[l].position != s_->scene.lights[l].position || end_lights[l].edge1 != s_->scene.lights[l].edge1 ||
          end_lights[l].edge2 != s_->scene.lights[l].edge2)
        throw Error(scene.source + ": an emitting triangle of a moving mesh lights the scene (lights of type "
                    "emissive must not move)");
    s_->motion = std::make_unique<MotionBvh>(device, s_->flat.geometry, end.geometry, motion_bounds, config);
    s_->shading = upload_scene(device, s_->scene, s_->flat, &end);
  }
  if (s_->timed()) {
    with_cl_errors([&] {
      cl::Program program = device.program("render/ray_times.cl", {});
      s_->queue_times = cl::Kernel(program, "queue_ray_times");
      s_->shadow_times = cl::Kernel(program, "shadow_ray_times");
    });
  }
  s_->queue.specialise_generation(s_->shading.generate_defines);
  s_->next.specialise_generation(s_->shading.generate_defines);
  if (config.precision == Precision::fast) s_->shading.defines.push_back("RTCL_FIXED_SPAWN_OFFSET");
  with_cl_errors([&] {
    cl::Program program = device.program("render/shade.cl", s_->shading.defines);
    s_->shade = cl::Kernel(program, "shade_hits");
    s_->accumulate = cl::Kernel(program, "accumulate_radiance");
    s_->totals = device.allocate(4 * sizeof(cl_uint), "compaction totals");
  });
}

Renderer::~Renderer() = default;

const RenderStats& Renderer::stats() const { return s_->stats; }
const Accel& Renderer::accel() const {
  if (s_->instanced)
    throw Error("Renderer::accel: " + s_->scene.source + " is traced through two levels (Renderer::scene), not one Accel");
  return s_->accel ? *s_->accel : *s_->motion;
}
bool Renderer::instanced() const { return s_->instanced != nullptr; }
const Scene* Renderer::scene() const { return s_->instanced ? &s_->instanced->scene() : nullptr; }
std::size_t Renderer::shading_bytes() const {
  if (s_->instanced) return s_->instanced->shading_bytes();
  const std::size_t t = std::max<std::uint32_t>(s_->shading.triangle_count, 1), sp = std::max<std::uint32_t>(s_->shading.sphere_count, 1);
  return (t * sizeof(ShadeTriangle) + sp * sizeof(ShadeSphere)) * (s_->motion ? 2 : 1);
}
double Renderer::build_ms() const { return s_->instanced ? s_->build_ms : accel().stats().build_ms; }

CommitStats Renderer::set_shutter(float open, float close) {
  if (!s_->instanced)
    throw Error("Renderer::set_shutter: " + s_->scene.source +
                " is traced by the flat path; a new shutter needs a new Renderer");
  auto start = std::chrono::steady_clock::now();
  CommitStats stats = s_->instanced->set_shutter(open, close);
  s_->build_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  s_->scene.camera.shutter_open = open;
  s_->scene.camera.shutter_close = close;
  return stats;
}
const std::vector<std::string>& Renderer::defines() const { return s_->shading.defines; }

// Per render: camera, shading constants, a cleared framebuffer.
void Renderer::prepare(const RenderSettings& settings, const ImageRegion& region) {
  check_settings(settings);
  State& s = *s_;
  s.settings = settings;
  s.region = checked_region(settings, region);
  s.stats = RenderStats{};
  const std::uint32_t pixels = s.region.width * s.region.height;
  CameraFrame frame = camera_frame(s.scene.camera, settings.width, settings.height);
  DeviceCamera camera{};
  store(camera.origin, frame.origin);
  store(camera.corner, frame.corner);
  store(camera.du, frame.du);
  store(camera.dv, frame.dv);
  camera.width = settings.width;
  camera.height = settings.height;
  const Camera& cam = s.scene.camera;
  double aperture = cam.aperture;
  store(camera.lens_u, glm::normalize(frame.du) * aperture);
  store(camera.lens_v, -glm::normalize(frame.dv) * aperture);
  camera.focus_distance = cam.focus_distance > 0.0f
                              ? cam.focus_distance
                              : static_cast<float>(glm::length(glm::dvec3(cam.look_at) - glm::dvec3(cam.position)));
  camera.sampler = static_cast<rtcl_u32>(settings.sampler);
  camera.seed = settings.seed;
  camera.filter = static_cast<rtcl_u32>(settings.filter);
  ShadeParams params{};
  store(params.ambient, glm::dvec3(s.scene.ambient));
  store(params.background, glm::dvec3(s.scene.background));
  params.min_weight = settings.min_weight;
  params.max_depth = settings.max_depth;
  params.triangle_count = s.shading.triangle_count;
  params.sampler = static_cast<rtcl_u32>(settings.sampler);
  params.seed = settings.seed;
  params.spp = settings.spp;
  params.light_samples = settings.light_samples;
  s.slots_per_ray = shadow_slots_per_ray(s.scene, settings.light_samples);
  params.shadow_slots = s.slots_per_ray;
  s.camera = s.device.upload(&camera, sizeof camera, "camera");
  s.params = s.device.upload(&params, sizeof params, "shading parameters");
  s.framebuffer = s.device.allocate(std::size_t(pixels) * RTCL_RADIANCE_BYTES, "framebuffer");
  with_cl_errors([&] {
    cl::Event cleared;
    s.device.queue().enqueueFillBuffer(s.framebuffer, cl_float4{}, 0, std::size_t(pixels) * RTCL_RADIANCE_BYTES, nullptr, &cleared);
    s.last = {cleared};
  });
}

Image Renderer::render(const RenderSettings& settings, const RenderProgress& progress) {
  return render(settings, ImageRegion{}, progress);
}

Image Renderer::render(const RenderSettings& settings, const ImageRegion& region, const RenderProgress& progress) {
  auto start = std::chrono::steady_clock::now();
  prepare(settings, region);
  State& s = *s_;
  const std::uint32_t pixels = s.region.width * s.region.height;
  const double total_work = double(pixels) * settings.spp;
  for (std::uint32_t sample = 0; sample < settings.spp; ++sample)
    for (std::uint32_t first = 0; first < pixels; first += settings.batch_pixels) {
      std::uint32_t count = std::min(settings.batch_pixels, pixels - first);
      s.sample = sample;
      generate(first, count, sample);
      trace_batch(count, double(sample) * pixels + first, total_work, progress, nullptr);
    }
  std::vector<cl_float4> sums = read_framebuffer(pixels);
  Image image;
  image.width = s.region.width;
  image.height = s.region.height;
  image.rgb.resize(std::size_t(pixels) * 3);
  const float inv = 1.0f / static_cast<float>(settings.spp);
  for (std::size_t p = 0; p < pixels; ++p)
    for (int c = 0; c < 3; ++c) image.rgb[p * 3 + c] = sums[p].s[c] * inv;
  finish_stats(start);
  if (progress) progress(1.0);
  return image;
}

PixelSamples Renderer::render_pixels(const RenderSettings& settings, const std::vector<std::uint32_t>& pixels) {
  auto start = std::chrono::steady_clock::now();
  prepare(settings, ImageRegion{});
  State& s = *s_;
  const std::size_t image_pixels = std::size_t(settings.width) * settings.height;
  std::vector<bool> listed(image_pixels, false);
  for (std::uint32_t p : pixels) {
    if (p >= image_pixels)
      throw Error("render_pixels: pixel " + std::to_string(p) + " is outside the " + std::to_string(settings.width) +
                  "x" + std::to_string(settings.height) + " image");
    if (listed[p]) throw Error("render_pixels: pixel " + std::to_string(p) + " is listed twice");
    listed[p] = true;
  }
  PixelSamples out;
  const auto n = static_cast<std::uint32_t>(pixels.size());
  out.rgb.resize(std::size_t(n) * 3);
  out.depth.resize(n);
  out.object.resize(n);
  if (n == 0) {
    finish_stats(start);
    return out;
  }
  if (std::uint64_t(n) * settings.spp > 0xffffffffull)
    throw Error("render_pixels: " + std::to_string(n) + " pixels times " + std::to_string(settings.spp) +
                " spp must be below 2^32 samples");
  const std::uint32_t slots = n * settings.spp;
  if (!s.shade_slots()) {
    std::vector<std::string> defines = s.shading.defines;
    defines.push_back("RTCL_PIXEL_SLOTS");
    with_cl_errors([&] { s.shade_slots = cl::Kernel(s.device.program("render/shade.cl", defines), "shade_hits"); });
  }
  // One framebuffer entry per slot (sample of a listed pixel).
  s.framebuffer = s.device.allocate(std::size_t(slots) * RTCL_RADIANCE_BYTES, "framebuffer");
  with_cl_errors([&] {
    cl::Event cleared;
    s.device.queue().enqueueFillBuffer(s.framebuffer, cl_float4{}, 0, std::size_t(slots) * RTCL_RADIANCE_BYTES,
                                       wait_list(s.last), &cleared);
    s.last = {cleared};
  });
  s.pixel_list = s.device.upload(pixels.data(), pixels.size() * sizeof(std::uint32_t), "pixel list");
  s.slots = true;
  std::vector<Hit> hits;
  try {
    for (std::uint32_t first = 0; first < slots; first += settings.batch_pixels) {
      std::uint32_t count = std::min(settings.batch_pixels, slots - first);
      cl::Event e = s.queue.generate_camera_rays_at(s.camera, s.pixel_list, first, count, settings.spp, s.last);
      s.generates.push_back(e);
      s.last = {e};
      s.stats.rays.camera += count;
      trace_batch(count, 0.0, 1.0, {}, &hits);
      for (std::uint32_t i = 0; i < count; ++i) {
        const std::uint32_t slot = first + i;
        if (slot % settings.spp != 0) continue;  // sample 0 gives the first hit
        const Hit& h = hits[i];
        const bool hit = h.prim >= 0;
        out.depth[slot / settings.spp] = hit ? h.t : INFINITY;
        const std::uint32_t material = !hit ? 0u
                                       : s.instanced ? s.instanced->material(s.first_objects.at(i), h.prim)
                                                     : s.flat.material.at(std::size_t(h.prim));
        out.object[slot / settings.spp] = hit ? static_cast<std::int32_t>(material) : -1;
      }
    }
  } catch (...) {
    s.slots = false;
    throw;
  }
  s.slots = false;
  std::vector<cl_float4> sums = read_framebuffer(slots);
  const float inv = 1.0f / static_cast<float>(settings.spp);
  for (std::uint32_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      float sum = 0.0f;  // in sample order
      for (std::uint32_t k = 0; k < settings.spp; ++k) sum += sums[std::size_t(i) * settings.spp + k].s[c];
      out.rgb[std::size_t(i) * 3 + c] = sum * inv;
    }
  finish_stats(start);
  return out;
}

void Renderer::trace_batch(std::uint32_t count, double done, double total_work, const RenderProgress& progress,
                           std::vector<Hit>* first_hits) {
  State& s = *s_;
  const RenderSettings& settings = s.settings;
  for (std::uint32_t generation = 0; s.queue.size() > 0; ++generation) {
    queue_times();
    trace(generation == 0);
    if (generation == 0 && first_hits) {
      first_hits->resize(s.queue.size());
      with_cl_errors([&] {
        s.device.queue().enqueueReadBuffer(s.hits.buffer(), CL_TRUE, 0, first_hits->size() * sizeof(Hit),
                                           first_hits->data(), wait_list(s.last));
        if (s.instanced) {
          s.first_objects.resize(first_hits->size());
          s.device.queue().enqueueReadBuffer(s.hit_objects.buffer(), CL_TRUE, 0,
                                             s.first_objects.size() * sizeof(cl_uint), s.first_objects.data(),
                                             wait_list(s.last));
        }
      });
    }
    advance_generation();
    s.stats.generations++;
    if (progress)
      progress((done + count * std::min(1.0, (generation + 1.0) / (settings.max_depth + 1.0))) / total_work);
  }
  collect_times();
}

void Renderer::advance_generation() {
  shade();
  compact();
  shadow_times();
  trace_shadows();
  accumulate();
  std::swap(s_->queue, s_->next);
}

std::vector<cl_float4> Renderer::read_framebuffer(std::size_t pixels) {
  State& s = *s_;
  static_assert(sizeof(cl_float4) == RTCL_RADIANCE_BYTES);
  std::vector<cl_float4> sums(pixels);
  with_cl_errors([&] {
    s.device.queue().enqueueReadBuffer(s.framebuffer, CL_TRUE, 0, sums.size() * RTCL_RADIANCE_BYTES, sums.data(),
                                       wait_list(s.last));
  });
  return sums;
}

void Renderer::finish_stats(std::chrono::steady_clock::time_point start) {
  State& s = *s_;
  s.stats.queue_bytes = s.queue.bytes() + s.next.bytes() + s.shadows.bytes() + s.hits.bytes() +
                        s.radiance.bytes() + s.spawn.rays.bytes() + s.spawn.paths.bytes() + s.spawn.flags.bytes() +
                        s.shadow_slots.rays.bytes() + s.shadow_slots.weights.bytes() +
                        s.shadow_slots.flags.bytes() + s.shadow_slots.index.bytes() + s.times.bytes() +
                        s.shadow_time.bytes();
  s.stats.render_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

std::vector<std::vector<TreeRay>> Renderer::ray_tree(const Ray& ray, const RenderSettings& settings) {
  prepare(settings, ImageRegion{});
  State& s = *s_;
  s.sample = 0;
  std::vector<std::vector<TreeRay>> tree;
  std::vector<Ray> rays{ray};
  std::vector<PathState> paths{PathState{0, 0, 1.0f, 1.0f, 1.0f}};
  s.queue.assign(rays, paths);
  while (s.queue.size() > 0) {
    s.queue.read(rays, paths, s.last);
    tree.emplace_back();
    for (std::size_t i = 0; i < rays.size(); ++i) tree.back().push_back(TreeRay{rays[i], paths[i]});
    queue_times();
    trace(tree.size() == 1);
    advance_generation();
  }
  collect_times();
  return tree;
}

// generate: camera rays of one batch, in screen-tile order.
void Renderer::generate(std::uint32_t first, std::uint32_t count, std::uint32_t sample) {
  State& s = *s_;
  const ImageRegion& r = s.region;
  cl::Event e = s.queue.generate_camera_rays(s.camera, first, count, sample, s.settings.spp, r.x0, r.y0, r.width,
                                             r.height, s.last);
  s.generates.push_back(e);
  s.last = {e};
  s.stats.rays.camera += count;
}

// trace: closest hit of every queued ray. Camera rays are generated in
// screen-tile order (8 consecutive rays = one tile row): coherent; reflected
// and refracted rays are not promised to be.
void Renderer::trace(bool camera_rays) {
  State& s = *s_;
  std::size_t n = s.queue.size();
  s.stats.peak_queue = std::max(s.stats.peak_queue, n);
  const cl::Buffer& hits = s.hits.reserve(s.device, n);
  Coherence coherence = camera_rays ? Coherence::coherent : Coherence::incoherent;
  if (s.instanced) {
    SceneBuffers extra;
    extra.instance_ids = s.hit_objects.reserve(s.device, n);
    if (s.instanced->moving()) extra.times = s.times.buffer();
    cl::Event e = s.instanced->scene().trace(Query::closest, s.queue.rays(), hits, n, extra, s.last, coherence);
    (camera_rays ? s.camera_traces : s.secondary_traces).push_back(e);
    s.last = {e};
    return;
  }
  cl::Event e = s.motion ? s.motion->trace(Query::closest, s.queue.rays(), RayTimes{s.times.buffer()}, hits, n, s.last, coherence)
                         : s.accel->trace(Query::closest, s.queue.rays(), hits, n, s.last, coherence);
  (camera_rays ? s.camera_traces : s.secondary_traces).push_back(e);
  s.last = {e};
}

// shade: local term, shadow-ray candidates, reflected and refracted rays.
void Renderer::shade() {
  State& s = *s_;
  std::size_t n = s.queue.size();
  s.radiance.reserve(s.device, n);
  s.shadow_slots.reserve(s.device, std::max<std::size_t>(n * s.slots_per_ray, 1));
  s.shadow_slots.count = n * s.slots_per_ray;
  s.spawn.reserve(s.device, 2 * n);
  with_cl_errors([&] {
    cl::Kernel& k = s.slots ? s.shade_slots : s.shade;
    cl_uint a = 0;
    k.setArg(a++, s.queue.rays());
    k.setArg(a++, s.hits.buffer());
    k.setArg(a++, s.queue.paths());
    k.setArg(a++, static_cast<cl_uint>(n));
    k.setArg(a++, s.shading.triangles);
    k.setArg(a++, s.shading.spheres);
    k.setArg(a++, s.shading.materials);
    k.setArg(a++, s.shading.lights);
    k.setArg(a++, s.params);
    k.setArg(a++, s.radiance.buffer());
    k.setArg(a++, s.shadow_slots.rays.buffer());
    k.setArg(a++, s.shadow_slots.weights.buffer());
    k.setArg(a++, s.shadow_slots.flags.buffer());
    k.setArg(a++, s.spawn.rays.buffer());
    k.setArg(a++, s.spawn.paths.buffer());
    k.setArg(a++, s.spawn.flags.buffer());
    k.setArg(a++, static_cast<cl_uint>(s.sample));
    k.setArg(a++, static_cast<cl_uint>(s.region.x0));
    k.setArg(a++, static_cast<cl_uint>(s.region.y0));
    k.setArg(a++, static_cast<cl_uint>(s.region.width));
    k.setArg(a++, static_cast<cl_uint>(s.settings.width));
    if (s.motion) {
      k.setArg(a++, s.shading.triangles_close);
      k.setArg(a++, s.shading.spheres_close);
    }
    if (s.slots) k.setArg(a++, s.pixel_list);
    if (s.instanced) {
      k.setArg(a++, s.instanced->instances());
      k.setArg(a++, s.hit_objects.buffer());
    }
    cl::Event e = launch(s.device, k, n, s.last);
    s.shades.push_back(e);
    s.last = {e};
  });
}

// compact: flagged slots -> the dense shadow queue and the next ray queue;
// their sizes are read back (the only host synchronisation per generation).
void Renderer::compact() {
  State& s = *s_;
  cl::Event first;
  cl::Event shadows = s.shadows.compact_from(s.shadow_slots, s.totals, 0, s.last, &first);
  cl::Event spawned = s.next.compact_from(s.spawn, s.totals, 2, {shadows});
  s.compacts.push_back({first, spawned});
  cl_uint totals[4] = {0, 0, 0, 0};
  std::vector<cl::Event> wait{spawned};
  with_cl_errors(
      [&] { s.device.queue().enqueueReadBuffer(s.totals, CL_TRUE, 0, sizeof totals, totals, &wait); });
  s.shadows.set_size(totals[0]);
  s.next.set_size(totals[2]);
  s.stats.rays.shadow += totals[0];
  s.stats.rays.refraction += totals[3];
  s.stats.rays.reflection += totals[2] - totals[3];
  s.last = {spawned};
}

// trace_shadows: any hit of every shadow ray. Coherent: the queue keeps the
// order of the rays that spawned them, so consecutive shadow rays leave
// neighbouring points towards the same few point lights.
void Renderer::trace_shadows() {
  State& s = *s_;
  if (s.shadows.size() == 0) return;
  if (s.instanced) {
    SceneBuffers extra;
    if (s.instanced->moving()) extra.times = s.shadow_time.buffer();
    cl::Event e = s.instanced->scene().trace(Query::any, s.shadows.rays(), s.shadows.hits(), s.shadows.size(), extra,
                                             s.last, Coherence::coherent);
    s.shadow_traces.push_back(e);
    s.last = {e};
    return;
  }
  cl::Event e = s.motion ? s.motion->trace(Query::any, s.shadows.rays(), RayTimes{s.shadow_time.buffer()},
                                           s.shadows.hits(), s.shadows.size(), s.last, Coherence::coherent)
                         : s.accel->trace(Query::any, s.shadows.rays(), s.shadows.hits(), s.shadows.size(), s.last,
                                          Coherence::coherent);
  s.shadow_traces.push_back(e);
  s.last = {e};
}

// queue_times (moving scenes): each queued ray's time, from its path's
// pixel and the sample being traced.
void Renderer::queue_times() {
  State& s = *s_;
  if (!s.timed()) return;
  std::size_t n = s.queue.size();
  s.times.reserve(s.device, std::max<std::size_t>(n, 1));
  with_cl_errors([&] {
    cl::Kernel& k = s.queue_times;
    cl_uint a = 0;
    k.setArg(a++, s.queue.paths());
    k.setArg(a++, static_cast<cl_uint>(n));
    k.setArg(a++, static_cast<cl_uint>(s.sample));
    k.setArg(a++, static_cast<cl_uint>(s.settings.spp));
    k.setArg(a++, static_cast<cl_uint>(s.settings.sampler));
    k.setArg(a++, static_cast<cl_uint>(s.settings.seed));
    k.setArg(a++, static_cast<cl_uint>(s.region.x0));
    k.setArg(a++, static_cast<cl_uint>(s.region.y0));
    k.setArg(a++, static_cast<cl_uint>(s.region.width));
    k.setArg(a++, static_cast<cl_uint>(s.settings.width));
    k.setArg(a++, s.times.buffer());
    k.setArg(a++, static_cast<cl_uint>(s.slots));
    k.setArg(a++, s.slots ? s.pixel_list : s.times.buffer());  // unread unless listed
    s.last = {launch(s.device, k, n, s.last)};
  });
}

// shadow_times (moving scenes): each shadow ray takes the time of the ray
// whose hit cast it.
void Renderer::shadow_times() {
  State& s = *s_;
  if (!s.timed() || s.shadows.size() == 0) return;
  s.shadow_time.reserve(s.device, s.shadows.size());
  with_cl_errors([&] {
    cl::Kernel& k = s.shadow_times;
    cl_uint a = 0;
    k.setArg(a++, s.times.buffer());
    k.setArg(a++, static_cast<cl_uint>(s.queue.size()));
    k.setArg(a++, static_cast<cl_uint>(s.slots_per_ray));
    k.setArg(a++, s.shadow_slots.flags.buffer());
    k.setArg(a++, s.shadow_slots.index.buffer());
    k.setArg(a++, s.shadow_time.buffer());
    s.last = {launch(s.device, k, s.queue.size(), s.last)};
  });
}

// accumulate: this generation's radiance, per pixel, into the framebuffer.
void Renderer::accumulate() {
  State& s = *s_;
  std::size_t n = s.queue.size();
  with_cl_errors([&] {
    cl::Kernel& k = s.accumulate;
    cl_uint a = 0;
    k.setArg(a++, s.queue.paths());
    k.setArg(a++, static_cast<cl_uint>(n));
    k.setArg(a++, s.radiance.buffer());
    k.setArg(a++, s.shadow_slots.weights.buffer());
    k.setArg(a++, s.shadow_slots.flags.buffer());
    k.setArg(a++, s.shadow_slots.index.buffer());
    k.setArg(a++, s.shadows.size() > 0 ? s.shadows.hits() : s.hits.buffer());
    k.setArg(a++, s.framebuffer);
    k.setArg(a++, static_cast<cl_uint>(s.slots_per_ray));
    cl::Event e = launch(s.device, k, n, s.last);
    s.accumulates.push_back(e);
    s.last = {e};
  });
}

// Adds the device times of the finished stages to the stats.
void Renderer::collect_times() {
  State& s = *s_;
  with_cl_errors([&] { cl::WaitForEvents(s.last); });
  auto sum = [&](std::vector<cl::Event>& events, double& ms) {
    if (s.device.profiling()) with_cl_errors([&] {
        for (const cl::Event& e : events) ms += event_ms(e);
      });
    events.clear();
  };
  sum(s.camera_traces, s.stats.camera_trace_ms);
  sum(s.secondary_traces, s.stats.secondary_trace_ms);
  sum(s.shadow_traces, s.stats.shadow_trace_ms);
  sum(s.generates, s.stats.generate_ms);
  sum(s.shades, s.stats.shade_ms);
  if (s.device.profiling()) with_cl_errors([&] {
      for (const auto& [first, last] : s.compacts) {
        auto start = first.getProfilingInfo<CL_PROFILING_COMMAND_START>();
        auto end = last.getProfilingInfo<CL_PROFILING_COMMAND_END>();
        s.stats.compact_ms += end > start ? static_cast<double>(end - start) * 1e-6 : 0.0;
      }
    });
  s.compacts.clear();
  sum(s.accumulates, s.stats.accumulate_ms);
}

}  // namespace rtcl
