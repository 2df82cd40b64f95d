// The scenes and ray sets every benchmark shares. Each scene has one fixed
// pinhole camera and one point light; its primary, shadow and diffuse-bounce
// rays are generated once and traced unchanged by every structure and by
// Embree, so that all of them measure the same rays.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/accel.hpp"
#include "bench/support/scene_catalog.hpp"
#include "bench/support/scenes_dir.hpp"
#include "rtcl/device.hpp"
#include "rtcl/layouts.hpp"
#include "rtcl/geometry.hpp"

namespace rtcl::bench {

enum class RayKind {
  primary,  // camera rays through pixel centres; closest hit
  shadow,   // primary hit point -> the point light (t in [0, 1]); any hit
  diffuse,  // primary hit point, cosine-distributed around the facing normal; closest hit
  // The same rays reordered for coherent packets (rtcl/render/ray_order.hpp):
  primary_tiled,   // primary in 8x8 screen-tile order
  shadow_morton,   // shadow in Morton order of (origin, direction)
  diffuse_morton,  // diffuse in Morton order of (origin, direction)
};
// The sets every backend measures (scanline / pixel order) ...
inline constexpr RayKind ray_kinds[] = {RayKind::primary, RayKind::shadow, RayKind::diffuse};
// ... and the reordered ones, measured for rtcl's structures.
inline constexpr RayKind ordered_ray_kinds[] = {RayKind::primary_tiled, RayKind::shadow_morton,
                                                RayKind::diffuse_morton};
const char* ray_kind_name(RayKind kind);
Query ray_kind_query(RayKind kind);

// Camera, SceneSpec and scene_specs(): bench/support/scene_catalog.hpp;
// scenes_dir(): bench/support/scenes_dir.hpp.

// The repository's scene file scenes/<name> (their mesh paths point at
// ../shared/scenes).
std::string repo_scene(const std::string& name);

// Image width = height in pixels: $RTCL_BENCH_RES, default 1024.
int image_size();

// Rays for brute force, which is O(rays x triangles): $RTCL_BENCH_BRUTE_RAYS,
// default 16384.
std::size_t brute_ray_limit();

// Threads for Embree's traversal: $RTCL_BENCH_THREADS, default the machine's
// hardware threads (PoCL's CPU device uses all of them too).
unsigned host_threads();

// The OpenCL device the rtcl benchmarks use ($RTCL_DEVICE or the first one),
// opened on first use. Throws Error when there is none.
const Device& bench_device();

// What answers the reference hits every ray set carries: "embree" when built
// in (independent of every structure under test), else rtcl's "bvh", else
// "brute".
std::string oracle_name();

struct RaySet {
  std::vector<Ray> rays;
  // The oracle's answers for the same rays. For Query::any only hit / miss is
  // meaningful (prim >= 0 means occluded).
  std::vector<Hit> reference;
  double hit_fraction() const;
};

struct BenchScene {
  const SceneSpec* spec = nullptr;
  Geometry geometry;  // validated
  int width = 0, height = 0;
  RaySet primary, shadow, diffuse;
  RaySet primary_tiled, shadow_morton, diffuse_morton;  // the same rays and references, reordered
  std::string oracle;  // what answered the reference hits: "embree" or an accel name
  double load_ms = 0.0, rays_ms = 0.0;

  const RaySet& rays(RayKind kind) const;
  std::size_t triangle_count() const { return geometry.triangles.size(); }
};

// The named scene (a SceneSpec name), loaded and with its ray sets generated
// on first use. Only one scene stays resident: asking for another releases it
// once no caller holds it. Throws Error for an unknown name or missing file.
std::shared_ptr<const BenchScene> bench_scene(const std::string& name);

// Every k-th ray (and its reference) with k = ceil(size / limit): the same
// spread over the image in at most `limit` rays.
RaySet subset(const RaySet& set, std::size_t limit);

// Fraction of hits that agree with the reference: same hit / miss and, for
// Query::closest, t within a relative 1e-3 (a different triangle at the same
// distance, e.g. across a shared edge, agrees).
double agreement(const std::vector<Hit>& hits, const RaySet& set, Query query);

// Benchmarks register per scene through hooks, so that the whole run proceeds
// scene by scene (one resident scene). Call at static initialisation;
// register_scene_benchmarks() runs every hook for every scene, in
// scene_specs() order and, within a scene, hook registration order.
using SceneHook = std::function<void(const SceneSpec&)>;
bool add_scene_hook(SceneHook hook);
void register_scene_benchmarks();

}  // namespace rtcl::bench
