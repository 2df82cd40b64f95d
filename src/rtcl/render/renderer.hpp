// Whitted ray tracing on the device as wavefront queues (lecture:
// IntersectColor). Per batch of camera rays:
//
//   generate ─► queue ─► trace (closest) ─► shade ─┬─► shadow slots ─► compact ─► trace (any) ─┐
//                 ▲                                 │                                          ▼
//                 └────────── compact ◄── spawn slots (reflection, refraction)     accumulate ─► framebuffer
//
// until the queue is empty or every path reached the depth limit. Each stage
// is one function of Renderer; the kernels are built with -D options from
// the scene (no refraction code without transmissive materials, no sphere
// code without spheres, no area-light, glossy or lens code without area
// lights, rough materials or an aperture; the light loop unrolled).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/accel/bvh_motion.hpp"
#include "rtcl/device.hpp"
#include "rtcl/render/image.hpp"
#include "rtcl/render/render_layouts.hpp"
#include "rtcl/render/sampling_options.hpp"
#include "rtcl/scene.hpp"
#include "rtcl/scene/scene_description.hpp"

namespace rtcl {

struct RenderSettings {
  std::uint32_t width = 512, height = 512;
  // Samples per pixel (anti-aliasing, and the pixel's share of every other
  // distributed effect); with the stratified sampler, 1 traces pixel centres.
  std::uint32_t spp = 1;
  // Where the samples of every distributed decision (sub-pixel position,
  // lens, light point, glossy direction) lie: kernels/shared/sampling.h.
  // Each pixel's samples are a pure function of (pixel, sample, seed).
  Sampler sampler = Sampler::stratified;
  std::uint32_t seed = 0;
  // Reconstruction filter, by filter importance sampling (sampling.h).
  Filter filter = Filter::box;
  // Shadow rays per area light and shading point (soft shadows; point
  // lights take one). Speed/accuracy knob.
  std::uint32_t light_samples = 1;
  // Reflection/refraction bounces after the camera ray's hit (0: local
  // shading and shadows only). Speed/accuracy knob.
  std::uint32_t max_depth = 5;
  // A spawned ray whose path weight's largest component is below this is
  // dropped: its contribution (at most this times the radiance it would
  // bring) is lost. Speed/accuracy knob; 0 keeps every ray.
  float min_weight = 1e-3f;
  // Camera rays per wavefront: more gives the device more parallel work and
  // costs about 300 bytes of queue memory per ray and light.
  std::uint32_t batch_pixels = 1u << 17;
};

// A rectangle of the image, in pixels from the top left; width or height 0:
// the whole image.
struct ImageRegion {
  std::uint32_t x0 = 0, y0 = 0, width = 0, height = 0;
};

struct RayCounts {
  std::uint64_t camera = 0, shadow = 0, reflection = 0, refraction = 0;
  std::uint64_t total() const { return camera + shadow + reflection + refraction; }
};

struct RenderStats {
  RayCounts rays;
  double render_ms = 0.0;  // wall clock of render(), kernels and transfers included
  // Device time of the kernels by stage (0 when the queue has no profiling);
  // compact_ms spans both compactions of a generation, first kernel start to
  // last kernel end.
  double camera_trace_ms = 0.0, secondary_trace_ms = 0.0, shadow_trace_ms = 0.0;
  double generate_ms = 0.0, shade_ms = 0.0, compact_ms = 0.0, accumulate_ms = 0.0;
  std::size_t peak_queue = 0;     // largest queue of camera/secondary rays
  std::size_t queue_bytes = 0;    // device memory of queues and slots at the end
  std::uint32_t generations = 0;  // trace rounds over all batches
};

// One ray of a ray tree (Renderer::ray_tree).
struct TreeRay {
  Ray ray;         // origin after the safe offset; unit direction
  PathState path;  // pixel, depth, weight
};

// The samples of a list of pixels (Renderer::render_pixels), parallel to
// the list.
struct PixelSamples {
  std::vector<float> rgb;            // 3 per pixel, linear: the mean of its spp samples
  std::vector<float> depth;          // distance along sample 0's camera ray to its first hit; +inf: a miss
  std::vector<std::int32_t> object;  // the material index of that hit; -1: a miss
};

// Called with the fraction of the work done, in [0, 1], after each
// generation of each batch.
using RenderProgress = std::function<void(double fraction)>;

class Renderer {
 public:
  // Flattens and validates the scene, builds the named acceleration
  // structure over it (with `config`: its precision level also picks the
  // spawn offsets, see kernels/render/shade.cl) and the kernels specialised
  // to it. A moving scene (rtcl/scene/motion.hpp) is flattened at the
  // camera's shutter open and close and traced by the MotionBvh with
  // `motion_bounds` (accel_name must then be "bvh"; the kernels get
  // RTCL_HAS_MOTION and each ray its sample's time); a static scene has no
  // time code. A scene whose meshes share a shape (shares_meshes) takes
  // the two-level path instead (instanced(): an rtcl::Scene with each shape
  // built once, docs/scenes-and-instances.md); accel_name must then name a
  // structure of the BVH family, and moving objects are moving instances
  // (motion_bounds unused). Throws Error.
  Renderer(const Device& device, const SceneDescription& scene, std::string_view accel_name, const AccelConfig& config = {},
           MotionBounds motion_bounds = MotionBounds::interpolated);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Renders the scene; deterministic for a given device and settings.
  // Throws Error naming the setting for an invalid one.
  Image render(const RenderSettings& settings, const RenderProgress& progress = {});
  // One region of that image, as an image of the region's size. Every pixel
  // starts from the same camera rays as in the whole-image render, its
  // secondary rays keep their relative queue order, and its radiance is
  // summed in the same order; a region whose x0 and y0 are multiples of
  // RTCL_TILE (8) also traces its camera rays in the same packets of 8. Such
  // regions give the whole image's pixels bit for bit, in any order and any
  // split, as long as a ray's hit does not depend on the rays that share its
  // packet (tests/render_region_test.cpp). Throws Error naming the region
  // when it is empty or leaves the image.
  Image render(const RenderSettings& settings, const ImageRegion& region, const RenderProgress& progress = {});

  // Only the listed pixels of the image (y * width + x, each at most once,
  // in any order): every sample of every listed pixel in the same launches
  // (batches of settings.batch_pixels samples), with the camera, light,
  // lens and glossy samples of render(settings), traced, shaded and
  // accumulated the same way. With 1 spp each pixel is that image's pixel
  // bit for bit; with more, the same up to the order in which a pixel's
  // float radiance is summed (here per sample, then over the samples in
  // sample order; there per generation into one sum). Its first hit
  // (depth, material) is that of sample 0's camera ray. For selective
  // tracing (selective.hpp). Throws Error naming a pixel outside the image
  // or listed twice.
  PixelSamples render_pixels(const RenderSettings& settings, const std::vector<std::uint32_t>& pixels);

  // The ray tree of one ray, for inspection and tests: generation 0 is
  // `ray` (weight 1, depth 0), generation g + 1 the reflected and refracted
  // rays that generation g spawns on the device (settings.max_depth and
  // min_weight apply), in queue order: per parent, reflection before
  // refraction. Ends with the first empty generation (not included).
  std::vector<std::vector<TreeRay>> ray_tree(const Ray& ray, const RenderSettings& settings);

  const RenderStats& stats() const;          // of the last render
  // The flat path's structure (the MotionBvh when the scene moves); Error
  // on the two-level path.
  const Accel& accel() const;
  // Whether the scene is traced through two levels; its Scene then (null
  // on the flat path): SceneStats counts the bottom levels built and the
  // device bytes of the structure.
  bool instanced() const;
  const Scene* scene() const;
  // Device bytes of the shading records (triangles, spheres and, on the
  // two-level path, one ShadeInstance per object).
  std::size_t shading_bytes() const;
  // Host build time of the structure (the Scene's commits on the two-level path).
  double build_ms() const;
  // Animations on the two-level path: the camera's shutter becomes [open,
  // close] (keyframe times) and each moving object is placed for it: its
  // transforms at open and close, committed (the top level is rebuilt,
  // never a bottom level). The same images as a Renderer built anew for
  // that shutter. Throws Error on the flat path (build a new Renderer) or
  // for a shutter that check_motion refuses; the renderer then stays as
  // it was.
  CommitStats set_shutter(float open, float close);
  const std::vector<std::string>& defines() const;  // the shade kernel's -D options

 private:
  struct State;
  std::unique_ptr<State> s_;

  void prepare(const RenderSettings& settings, const ImageRegion& region);
  // Traces the queued camera rays of one batch through every generation;
  // with `first_hits`, reads back their closest hits first.
  void trace_batch(std::uint32_t count, double done, double total_work, const RenderProgress& progress,
                   std::vector<Hit>* first_hits);
  std::vector<cl_float4> read_framebuffer(std::size_t pixels);
  void finish_stats(std::chrono::steady_clock::time_point start);
  void generate(std::uint32_t first, std::uint32_t count, std::uint32_t sample);
  void trace(bool camera_rays);
  void shade();
  void compact();
  void trace_shadows();
  void queue_times();
  void shadow_times();
  void accumulate();
  // After a generation's trace: shade, compact, the shadow rays, accumulate,
  // and the spawned rays become the queue.
  void advance_generation();
  void collect_times();
};

}  // namespace rtcl
