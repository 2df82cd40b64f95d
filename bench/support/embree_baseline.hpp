// Embree 3 as the yardstick: the same triangles and spheres in one Embree scene, traced
// by host threads over our Ray records, one ray at a time (rtcIntersect1 /
// rtcOccluded1) or in packets of eight consecutive rays (rtcIntersect8 /
// rtcOccluded8, the groups rtcl's packet kernels take), answering into our
// Hit records. Built (library rtcl_embree, define RTCL_HAVE_EMBREE) only
// when CMake finds Embree 3; `rtcl bench` and bench/ use it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "rtcl/accel.hpp"
#include "rtcl/accel/build_tree.hpp"
#include "rtcl/layouts.hpp"
#include "rtcl/geometry.hpp"

namespace rtcl::bench {

enum class EmbreeQuality {
  standard,  // RTC_BUILD_QUALITY_MEDIUM, Embree's default: binned SAH
  high,      // RTC_BUILD_QUALITY_HIGH: SAH with spatial splits, slower build
};

enum class EmbreeApi {
  single,   // rtcIntersect1 / rtcOccluded1, incoherent context (Embree's default)
  packet8,  // rtcIntersect8 / rtcOccluded8 over rays 8k .. 8k + 7, coherent context
};
const char* embree_api_name(EmbreeApi api, Query query);  // e.g. "rtcIntersect8"

class EmbreeScene {
 public:
  // Builds a scene with one triangle mesh and, where the geometry has
  // spheres, one geometry of Embree's sphere points; hits report our
  // primitive ids (triangles, then spheres). Throws Error for spheres when
  // this Embree has no point geometry.
  // `threads`: Embree's build threads (the first scene's count configures
  // the process's one Embree device). `robust`: RTC_SCENE_FLAG_ROBUST
  // (Embree's watertight mode, "avoid optimizations that reduce arithmetic
  // accuracy"), else RTC_SCENE_FLAG_NONE, Embree's default. Throws Error
  // with Embree's error code on failure.
  EmbreeScene(const Geometry& geometry, EmbreeQuality quality, unsigned threads, bool robust = false);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // Wall-clock ms of geometry setup + rtcCommitScene (Embree builds with TBB).
  double build_ms() const { return build_ms_; }
  // Bytes Embree allocated for the scene and kept after the build (its memory
  // monitor); the vertex and index arrays are shared with us, not counted.
  std::size_t bytes() const { return bytes_; }

  // Answers rays[0 .. count) into hits[0 .. count) on `threads` host threads
  // taking blocks of rays from a shared counter. Query::closest: t, u, v, prim
  // of the nearest hit (u, v as in Hit). Query::any: Embree reports no hit
  // data, so an occluded ray gets t = tmin, prim = 0, u = v = 0. Misses as Hit.
  void trace(Query query, const Ray* rays, Hit* hits, std::size_t count, unsigned threads,
             EmbreeApi api = EmbreeApi::single) const;

  // The same in three steps, so that only the traversal is timed, as
  // Embree's own framing has it (rays built before the loop, answers read
  // after it; rtcl's kernel time likewise excludes upload and read-back):
  // prepare() converts the rays into Embree's records, trace_prepared()
  // answers them in place on `threads` host threads, answers() converts
  // them into Hit records. prepare() again before each trace_prepared().
  void prepare(Query query, const Ray* rays, std::size_t count, EmbreeApi api = EmbreeApi::single) const;
  void trace_prepared(unsigned threads) const;
  void answers(Hit* hits) const;

 private:
  void build(const Geometry& geometry, EmbreeQuality quality, unsigned threads, bool robust);
  void release();
  struct Buffers;
  struct Prepared;
  void* scene_ = nullptr;  // RTCScene
  Buffers* buffers_ = nullptr;
  mutable std::shared_ptr<Prepared> prepared_;
  double build_ms_ = 0.0;
  std::size_t bytes_ = 0;
};

// Embree's binned SAH builder (rtcBuildBVH at RTC_BUILD_QUALITY_MEDIUM, the
// builder behind its default scene build) as a BvhConfig::custom_builder:
// a binary tree over bounds[i] / ids[i] with leaves of 1..8 primitives,
// costed as rtcl's SAH is (a node 0.5, a block of up to eight primitives
// 1), built on the process's Embree device. Throws Error when Embree fails.
BuildTree embree_binary_tree(std::span<const Aabb> bounds, std::span<const std::uint32_t> ids, unsigned threads);

// The library version, e.g. "3.13.5" (opens the Embree device with
// `threads` if no scene did).
std::string embree_version(unsigned threads);
// Whether this Embree traces 8-wide packets natively (RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED).
bool embree_has_packet8(unsigned threads);

}  // namespace rtcl::bench
