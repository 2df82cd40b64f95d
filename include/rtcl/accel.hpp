// Public API: an acceleration structure built over a Geometry (make_accel)
// and its queries, on host arrays or on the caller's OpenCL buffers. Every
// structure answers every ray query with the same Ray / Hit records; callers
// never depend on which structure answers (docs/api.md).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rtcl/accel_options.hpp"
#include "rtcl/device.hpp"
#include "rtcl/geometry.hpp"
#include "rtcl/precision.hpp"
#include "rtcl/queries.hpp"

namespace rtcl {

// What a trace call promises about the order of its rays; it picks the
// kernel (Accel::rays_per_work_item), never the answer: the closest hit's t
// is the same either way (on an exact tie of t, or for Query::any, which of
// the hit primitives is reported may differ).
enum class Coherence {
  // No promise: reflections and refractions, rays in arbitrary order, and
  // rays whose order is good for single rays (camera rays in pixel order,
  // shadow rays towards one light). Each work-item traces one ray, in the
  // caller's order.
  incoherent,
  // Each consecutive group of 8 rays (0-7, 8-15, ...) is alike: nearby
  // origins, similar directions. E.g. camera rays in 8x8 screen-tile order
  // (a group is one tile row), shadow rays towards one light in pixel, tile
  // or Morton order (render/ray_order.hpp). A structure with a packet kernel
  // traces each group in one work-item; the others treat it as incoherent.
  coherent,
  // Many rays whose neighbours are unrelated: diffuse and glossy bounces
  // from hits in pixel order. On CPU devices a structure with a single-ray
  // kernel may first sort them on the device by their origin's cell and
  // direction's octant, trace them in that order and write each hit at its
  // ray's index, which pays where a ray visits many nodes. Whether a call
  // sorts is AccelConfig::scattered_sort's choice. Elsewhere as incoherent.
  scattered,
};

// Whether Coherence::scattered calls sort their rays first.
enum class ScatteredSort {
  measured,  // the faster of the two as the structure's own calls measure it
  always,    // every scattered call sorts
  never,     // no call sorts (scattered calls trace as incoherent ones)
};

// How a structure is built and which kernels it compiles.
struct AccelConfig {
  Precision precision = Precision::robust;
  // The structure's build options (rtcl/accel_options.hpp), checked against
  // its declaration by make_accel; absent ones take the declared defaults
  // (`rtcl structures` lists them).
  AccelOptions options;
  ScatteredSort scattered_sort = ScatteredSort::measured;
};

struct AccelStats {
  double build_ms = 0.0;             // host build + flatten, without upload
  std::size_t device_bytes = 0;      // structure + primitive data on the device
  std::size_t primitive_count = 0;   // primitives stored (zero-area triangles skipped)
  std::size_t zero_area_skipped = 0;
  std::size_t node_count = 0;        // inner nodes (0 for brute force)
  std::size_t leaf_count = 0;        // primitive blocks
  Aabb bounds;                       // the geometry's box
};

// When Accel::refit asks for a rebuild (docs/api.md, "Refit").
struct RefitPolicy {
  // A refit whose tree's SAH cost exceeds max_cost_ratio times the cost at
  // the build sets RefitStats::needs_rebuild (refit_or_rebuild then builds
  // anew). The ratio understates the traces' slowdown: after ten refits of
  // a growing smooth deformation (bench/refit/refit_bench.cpp), at ratios
  // of 1.24-1.34, the bunny, the dragon and a 1M-triangle soup traced
  // 1.1-2.1x slower than on fresh builds; 1.2 rebuilds before that.
  // >= 1; +inf: never on cost.
  double max_cost_ratio = 1.2;
};

// What one Accel::refit (or refit_or_rebuild) did.
struct RefitStats {
  double refit_ms = 0.0;    // wall time of the call: checks, upload, device update, read-back
  // The tree's SAH cost: the expected wide-node visits (weight 0.5) plus
  // block tests (weight 1) of a ray crossing the root box, each child box
  // weighted by its area relative to the root's. At the build, and now
  // (after the refit; the build's when refused or rebuilt).
  double build_cost = 0.0;
  double cost = 0.0;
  double cost_ratio() const { return build_cost > 0.0 ? cost / build_cost : 1.0; }
  // The refit changed nothing: the structure still answers for the
  // previous vertices (`reason` says why). Only refit_or_rebuild rebuilds.
  bool refused = false;
  // Build the structure anew for these vertices (make_accel): refused, or
  // cost_ratio() above RefitPolicy::max_cost_ratio (the refit itself is
  // done and correct; the tree is only slow).
  bool needs_rebuild = false;
  bool rebuilt = false;     // refit_or_rebuild built it anew
  std::string reason;       // why needs_rebuild or rebuilt; empty otherwise
};

namespace detail {
struct AccelAccess;
}

class Accel {
 public:
  virtual ~Accel();
  Accel(const Accel&) = delete;
  Accel& operator=(const Accel&) = delete;

  const std::string& name() const { return name_; }
  const AccelStats& stats() const { return stats_; }
  const Device& device() const { return device_; }
  Precision precision() const { return precision_; }

  // ---- Queries on host arrays --------------------------------------------
  // Thread-safe: any number of host threads may query one structure at
  // once; each call holds the structure's lock while its batches run
  // (docs/api.md, "Threads"). Any number of rays: the library uploads,
  // traces and reads back in batches that fit the device's buffers. Invalid
  // rays (NaN or infinite components, a zero direction, an empty or NaN
  // [tmin, tmax]) are misses. Bad arguments throw Error naming the
  // argument before anything is written.

  // Closest (Query::closest) or any (Query::any) hit of every ray into
  // hits[i]; hits.size() must equal rays.size().
  void trace(Query query, const Rays& rays, std::span<Hit> hits, Coherence coherence = Coherence::incoherent) const;
  // The closest hit of every ray.
  std::vector<Hit> intersect(const Rays& rays, Coherence coherence = Coherence::incoherent) const;
  // 1 where some primitive lies on the ray within [tmin, tmax], else 0.
  std::vector<std::uint8_t> occluded(const Rays& rays, Coherence coherence = Coherence::incoherent) const;
  // The number of surface crossings of every ray within [tmin, tmax]
  // (docs/api.md, "Counting crossings": a crossing through a shared edge
  // or vertex counts once). counts.size() must equal rays.size().
  void count(const Rays& rays, std::span<std::uint32_t> counts) const;
  std::vector<std::uint32_t> count(const Rays& rays) const;
  // Every crossing of every ray within [tmin, tmax] (as count counts them),
  // sorted by t; at most max_hits_per_ray (>= 1) nearest of each ray.
  AllHits all_hits(const Rays& rays, std::uint32_t max_hits_per_ray = kAllHitsUnlimited) const;
  // For every point the nearest point of the surface within max_distance
  // (>= 0; +inf: anywhere), else a PointHit with prim = -1.
  void closest_points(const Points& points, std::span<PointHit> out,
                      float max_distance = kUnlimitedDistance) const;
  std::vector<PointHit> closest_points(const Points& points, float max_distance = kUnlimitedDistance) const;
  // The distance of every point to the surface (the closest point's).
  std::vector<float> distance(const Points& points) const;
  // The distance, negative inside a closed surface. Inside or outside is
  // the majority of nsamples (odd, >= 1) rays' crossing parities, as
  // Open3D's RaycastingScene::compute_signed_distance.
  std::vector<float> signed_distance(const Points& points, unsigned nsamples = 1) const;
  // 1 inside a closed surface, else 0, decided as signed_distance's sign.
  std::vector<std::uint8_t> occupancy(const Points& points, unsigned nsamples = 1) const;

  // ---- Queries on the caller's OpenCL buffers ----------------------------
  // Enqueues the query for rays[0 .. ray_count) into hits[0 .. ray_count) on
  // the device's queue after `wait`; returns the kernel's event. `coherence`
  // is the caller's promise about the ray order (see Coherence); a wrong
  // promise costs speed, never correctness. Throws Error when a buffer is
  // smaller than ray_count records. Thread-safe (the enqueue holds the
  // structure's lock).
  cl::Event trace(Query query, const cl::Buffer& rays, const cl::Buffer& hits, std::size_t ray_count,
                  const std::vector<cl::Event>& wait = {}, Coherence coherence = Coherence::incoherent) const;
  // The same on a caller's raw buffers (retained for the call, not owned):
  // for applications on the OpenCL C API.
  cl::Event trace(Query query, cl_mem rays, cl_mem hits, std::size_t ray_count,
                  const std::vector<cl::Event>& wait = {}, Coherence coherence = Coherence::incoherent) const;
  // Crossing counts (one cl_uint per ray) of rays[0 .. ray_count).
  cl::Event count(const cl::Buffer& rays, const cl::Buffer& counts, std::size_t ray_count,
                  const std::vector<cl::Event>& wait = {}) const;
  // Closest points (PointHit records) of points[0 .. point_count), each
  // point three floats (x, y, z; 12 bytes).
  cl::Event closest_points(const cl::Buffer& points, const cl::Buffer& out, std::size_t point_count,
                           float max_distance = kUnlimitedDistance, const std::vector<cl::Event>& wait = {}) const;

  // ---- Updates -------------------------------------------------------------
  // Whether refit is supported: the BVH family ("bvh", "bvh-ploc",
  // "bvh-packet"); other structures are built anew (refit_or_rebuild).
  bool supports_refit() const { return refittable(); }
  // Moves the structure to geometry's vertices, keeping its tree: every
  // primitive block is filled again from the vertices and every node's
  // child boxes are recomputed bottom-up on the device, in place (the
  // first refit allocates its inputs' buffers, later ones reuse them).
  // `geometry` must have the build's triangle, vertex and sphere counts
  // and its spheres unchanged; the triangles (indices) should be the
  // build's: they are compared with the last refit's and read again when
  // they differ, so that other indices still give right answers, only from
  // a slower tree. Thread-safe: holds the structure's lock
  // (queries wait; stats() is not synchronised with it).
  // Throws Error, the structure unchanged, when the structure does not
  // support refit (naming it and those that do), for a count or sphere
  // that differs (naming geometry.vertices, .triangles or .spheres) and
  // for a NaN/Inf vertex or an out-of-range index (naming it). Returns
  // refused + needs_rebuild, the structure unchanged, when a triangle
  // skipped at the build for zero area has an area now (the tree has no
  // place for it); needs_rebuild alone when the cost passes the policy's
  // threshold.
  RefitStats refit(const Geometry& geometry, const RefitPolicy& policy = {});

  // ---- Kernels and measurement (benchmarks, tuning) ----------------------
  // Consecutive rays one work-item traces in calls of this coherence: 1
  // (single-ray kernel) or 8 (packet kernel).
  std::size_t rays_per_work_item(Coherence coherence) const;
  // For Query::any in calls of this coherence: how many rays (packets, for
  // a packet kernel) one work-item traces in turn, each first tested
  // against the leaf that blocked the previous one; 1: no such test.
  std::size_t occluder_run(Coherence coherence) const;
  // Whether calls of this coherence may sort the rays first
  // (Coherence::scattered on a CPU device, a single-ray kernel, and
  // AccelConfig::scattered_sort not `never`).
  bool sorts(Coherence coherence) const;
  // Whether the latest trace call sorted its rays.
  bool last_call_sorted() const;
  // Whether the choice for scattered calls of this query is made: both ways
  // measured (each after its first launch), or a policy other than
  // `measured`, or calls that never sort. A benchmark warms up until it
  // holds.
  bool sort_choice_settled(Query query) const;
  // The -D options (and -cl-... flags) its trace programs are built with,
  // before the query's RTCL_QUERY_CLOSEST / RTCL_QUERY_ANY.
  const std::vector<std::string>& build_options() const { return defines_; }
  // The first command the latest trace call enqueued: the sort's first pass
  // for a call that sorts, else the kernel (trace's event).
  const cl::Event& first_event() const;
  // The latest call's time on the device in ms, from first_event()'s start
  // to the end of `done`, the event it returned (waits for it; needs a
  // profiling queue, Device::profiling()).
  double last_call_ms(const cl::Event& done) const;

 protected:
  // For the library's structures (not part of the stable API): the trace
  // kernels of one kernel file. "accel/bvh.cl" defines trace_closest_bvh
  // when built with -DRTCL_QUERY_CLOSEST and trace_any_bvh with
  // -DRTCL_QUERY_ANY (two specialised programs, each built at the first
  // query of its kind). Each work-item traces rays_per_work_item
  // consecutive rays (1, or 8 for a packet kernel); a launch covers
  // ceil(ray_count / rays_per_work_item) work-items. A file whose any-hit
  // kernel keeps the previous ray's or packet's occluder
  // (RTCL_TRACE_KERNELS_OCCLUDER_CACHE, kernels/shared/trace.h;
  // RTCL_PACKET_KERNELS_OCCLUDER_CACHE, kernels/shared/packet.h) is
  // launched with occluder_run times as many rays per work-item for
  // Query::any.
  struct TraceKernels {
    std::string file;
    std::size_t rays_per_work_item = 1;
    std::size_t occluder_run = 1;
    // Its single-ray kernels come from RTCL_TRACE_KERNELS* (kernels/shared/trace.h),
    // which read the rays through an order when built with RTCL_TRACE_ORDER
    // (Coherence::scattered).
    bool sortable = true;
  };
  // `incoherent` serves Coherence::incoherent calls, and coherent ones too
  // when `coherent` is absent. Both are built with `defines` plus the
  // precision level's options, each (coherence, query) program at its first
  // call. The constructor builds the incoherent closest-hit program, so
  // that a bad kernel fails at construction. Throws Error when the device
  // cannot run config.precision.
  Accel(const Device& device, std::string name, TraceKernels incoherent, std::optional<TraceKernels> coherent,
        std::vector<std::string> defines, AccelStats stats, const AccelConfig& config);
  // Sets the structure's kernel arguments, starting at argument `first`.
  virtual void set_structure_args(cl::Kernel& kernel, cl_uint first) const = 0;
  // Sets arguments that change with each trace call (after rays, hits and
  // ray_count; a structure with such arguments starts its own after them):
  // per-ray data such as ray times (MotionBvh). Called before every launch.
  virtual void set_call_args(cl::Kernel&) const {}
  // Whether set_structure_args sets exactly the plain 8-wide BVH's buffers
  // (Bvh8Node nodes, TriangleBlock and SphereBlock leaves), which the count,
  // all-hits and closest-point kernels (kernels/query/) walk.
  virtual bool plain_bvh8() const { return false; }
  // Refit support (Accel::refit): refit_structure runs with the lock held,
  // after refit checked that refittable(); it sets *bounds to the new
  // geometry's box when it changes the structure.
  virtual bool refittable() const { return false; }
  virtual RefitStats refit_structure(const Geometry& geometry, const RefitPolicy& policy, Aabb* bounds);

 private:
  friend struct detail::AccelAccess;
  struct State;  // kernels, the ray sort and its choice, the lock (accel/accel_state.hpp)
  cl::Event trace_locked(Query query, const cl::Buffer& rays, const cl::Buffer& hits, std::size_t ray_count,
                         const std::vector<cl::Event>& wait, Coherence coherence) const;

  Device device_;
  std::string name_;
  AccelStats stats_;
  Precision precision_;
  std::vector<std::string> defines_;  // structure's, then the precision level's
  std::unique_ptr<State> state_;
};

// Names make_accel accepts, in the order benchmarks list them.
std::vector<std::string> accel_names();

// Builds the named structure over validated geometry and uploads it: the
// one way to make a structure. `name` is a structure name or a spec with
// options, "grid:lambda=4,res=64x32x16" (parse_accel_spec); config.options
// are applied after the spec's; the options are checked and completed with
// their declared defaults here, once. Throws Error naming `name` when the
// structure or an option is unknown, of the wrong type or out of range
// (make_accel name "grid:lambda=-1": lambda must be > 0 and <= 1024), and
// naming the level when the device cannot run config.precision
// (precision "exact": ...).
std::unique_ptr<Accel> make_accel(const Device& device, std::string_view name, const Geometry& geometry,
                                  const AccelConfig& config = {});

// Brings `accel` (made by make_accel(device, name, ..., config)) to
// geometry's new vertices: refits it where its structure supports refit,
// else, or when the refit is refused or passes policy.max_cost_ratio,
// replaces it with make_accel(accel->device(), name, geometry, config)
// (RefitStats::rebuilt, `reason` says why). Errors as refit's and
// make_accel's; on an error `accel` is unchanged.
RefitStats refit_or_rebuild(std::unique_ptr<Accel>& accel, std::string_view name, const Geometry& geometry,
                            const AccelConfig& config = {}, const RefitPolicy& policy = {});

}  // namespace rtcl
