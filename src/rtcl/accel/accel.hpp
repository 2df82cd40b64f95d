// The interface every acceleration structure implements: built over a
// Geometry, queried with Ray buffers, answering into Hit buffers. Callers
// never depend on which structure answers.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rtcl/accel/options.hpp"
#include "rtcl/accel/precision.hpp"
#include "rtcl/accel/ray_sort.hpp"
#include "rtcl/accel/sort_choice.hpp"
#include "rtcl/cl/device.hpp"
#include "rtcl/scene/geometry.hpp"

namespace rtcl {

enum class Query {
  closest,  // nearest hit in [tmin, tmax]
  any,      // some hit in [tmin, tmax] (occlusion); t and prim of that hit
};

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
  // direction's octant (RaySort, rtcl/accel/ray_sort.hpp), trace them in
  // that order and write each hit at its ray's index: one more pass over
  // the rays and two over their keys, which pay where a ray visits many
  // nodes (README "Scattered rays sorted on the device"). Whether a call
  // sorts is AccelConfig::scattered_sort's choice; by default the faster
  // way as the structure's earlier scattered calls measured it
  // (SortChoice). Elsewhere as incoherent.
  scattered,
};

// How a structure is built and which kernels it compiles.
struct AccelConfig {
  Precision precision = Precision::robust;
  // The structure's build options (rtcl/accel/options.hpp), checked against
  // its declaration by make_accel; absent ones take the declared defaults
  // (`rtcl structures` lists them).
  AccelOptions options;
  // Whether Coherence::scattered calls sort (SortChoice): measured, always
  // or never.
  ScatteredSort scattered_sort = ScatteredSort::measured;
};

struct AccelStats {
  double build_ms = 0.0;             // host build + flatten, without upload
  std::size_t device_bytes = 0;      // structure + primitive data on the device
  std::size_t primitive_count = 0;   // primitives stored (zero-area triangles skipped)
  std::size_t zero_area_skipped = 0;
  std::size_t node_count = 0;        // inner nodes (0 for brute force)
  std::size_t leaf_count = 0;        // primitive blocks
  Aabb bounds;                       // the geometry's box (RaySort's grid of origins)
};

class Accel {
 public:
  virtual ~Accel() = default;
  Accel(const Accel&) = delete;
  Accel& operator=(const Accel&) = delete;

  const std::string& name() const { return name_; }
  const AccelStats& stats() const { return stats_; }
  const Device& device() const { return device_; }
  Precision precision() const { return precision_; }

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
  bool last_call_sorted() const { return last_sorted_; }
  // Whether the choice for scattered calls of this query is made: both ways
  // measured (each after its first launch, whose time includes PoCL's code
  // generation and the buffers' first touch), or a policy other than
  // `measured`, or calls that never sort. Records a finished pending call
  // first. A benchmark warms up until it holds.
  bool sort_choice_settled(Query query) const;

  // The -D options (and -cl-... flags) its trace programs are built with,
  // before the query's RTCL_QUERY_CLOSEST / RTCL_QUERY_ANY.
  const std::vector<std::string>& build_options() const { return defines_; }

  // Enqueues the query for rays[0 .. ray_count) into hits[0 .. ray_count) on
  // the device's queue after `wait`; returns the kernel's event. `coherence`
  // is the caller's promise about the ray order (see Coherence); a wrong
  // promise costs speed, never correctness. Throws Error when a buffer is
  // smaller than ray_count records. Not thread-safe per Accel.
  cl::Event trace(Query query, const cl::Buffer& rays, const cl::Buffer& hits, std::size_t ray_count,
                  const std::vector<cl::Event>& wait = {}, Coherence coherence = Coherence::incoherent) const;
  // The same on a caller's raw buffers (retained for the call, not owned):
  // for applications on the OpenCL C API.
  cl::Event trace(Query query, cl_mem rays, cl_mem hits, std::size_t ray_count,
                  const std::vector<cl::Event>& wait = {}, Coherence coherence = Coherence::incoherent) const;
  // The first command the latest trace call enqueued: the sort's first pass
  // for a call that sorts, else the kernel (trace's event).
  const cl::Event& first_event() const { return first_event_; }
  // The latest call's time on the device in ms, from first_event()'s start
  // to the end of `done`, the event it returned (waits for it; needs a
  // profiling queue, Device::profiling()).
  double last_call_ms(const cl::Event& done) const;

 protected:
  // The trace kernels of one kernel file: "accel/bvh.cl" defines
  // trace_closest_bvh when built with -DRTCL_QUERY_CLOSEST and
  // trace_any_bvh with -DRTCL_QUERY_ANY (two specialised programs, each
  // built at the first query of its kind). Each work-item traces
  // rays_per_work_item consecutive rays (1, or 8 for a packet kernel); a
  // launch covers ceil(ray_count / rays_per_work_item) work-items. A file
  // whose any-hit kernel keeps the previous ray's or packet's occluder
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
  // call: a caller that never makes one never pays its build. The
  // constructor builds the incoherent closest-hit program, so that a bad
  // kernel fails at construction. Throws Error when the device cannot run
  // config.precision.
  Accel(const Device& device, std::string name, TraceKernels incoherent, std::optional<TraceKernels> coherent,
        std::vector<std::string> defines, AccelStats stats, const AccelConfig& config);
  // Sets the structure's kernel arguments, starting at argument `first`.
  virtual void set_structure_args(cl::Kernel& kernel, cl_uint first) const = 0;
  // Sets arguments that change with each trace call (after rays, hits and
  // ray_count; a structure with such arguments starts its own after them):
  // per-ray data such as ray times (MotionBvh). Called before every launch.
  virtual void set_call_args(cl::Kernel&) const {}

 private:
  struct QueryKernel {
    cl::Kernel kernel;
    bool args_set = false;  // set_structure_args done (at its first trace: the constructor runs before the structure exists)
    std::uint64_t launches = 0;
  };
  // One kernel per query of one TraceKernels, each built at its first use;
  // `ordered`: built with RTCL_TRACE_ORDER, its argument 3 the sort's order.
  struct KernelSet {
    TraceKernels spec;
    std::optional<QueryKernel> closest, any;
    bool ordered = false;
  };
  KernelSet& set_for(Coherence coherence) const;
  QueryKernel& kernel_for(KernelSet& set, Query query) const;
  // Whether this call of the coherence sorts: asks the query's SortChoice,
  // after recording the query's pending measured call if it has finished.
  bool sort_this_call(Coherence coherence, Query query) const;
  void record_pending(Query query) const;

  // A scattered call whose device time is still to be recorded.
  struct PendingCall {
    bool sorted = false;
    cl::Event first, done;
    std::size_t ray_count = 0;
  };

  Device device_;
  std::string name_;
  AccelStats stats_;
  Precision precision_;
  std::vector<std::string> defines_;  // structure's, then the precision level's
  mutable KernelSet incoherent_;
  mutable std::optional<KernelSet> coherent_, scattered_;
  mutable std::unique_ptr<RaySort> sort_;  // at the first call that sorts
  mutable cl::Event first_event_;
  mutable bool last_sorted_ = false;
  // Per query (closest, any): the choice and its call in flight.
  mutable std::array<SortChoice, 2> sort_choices_;
  mutable std::array<std::optional<PendingCall>, 2> pending_;
};

// Names make_accel accepts, in the order benchmarks list them.
std::vector<std::string> accel_names();

// Builds the named structure over validated geometry and uploads it. `name`
// is a structure name or a spec with options, "grid:lambda=4,res=64x32x16"
// (parse_accel_spec); config.options are applied after the spec's. Throws
// Error naming the accel when the name is unknown or an option is unknown,
// of the wrong type or out of range, and naming --precision when the device
// cannot run config.precision.
std::unique_ptr<Accel> make_accel(const Device& device, std::string_view name, const Geometry& geometry,
                                  const AccelConfig& config = {});

// Occluder runs (Accel::TraceKernels::occluder_run) of a structure whose
// any-hit kernels have them (the BVHs, the kd-tree, the BSP, the grid and
// the octrees): the structure's `occluder_run` option when > 0, else
// kCpuOccluderRun on CPU devices and 1 on others (a GPU needs every ray or
// packet as a work-item of its own to fill its lanes).
inline constexpr std::uint32_t kCpuOccluderRun = 16;
std::size_t occluder_run_for(std::uint32_t requested, const DeviceInfo& device);
// That option, as such structures declare it.
OptionSpec occluder_run_option();

// Whether a structure's packet kernel serves its Coherence::coherent calls
// (`bvh`, `bvh-ploc` and `kdtree`; `bvh-packet` and `kdtree-packet` take it
// for every call): on CPU devices, where a packet's eight rays fill a
// work-item's float8 lanes; not on others, where every ray is a work-item
// of its own (an NVIDIA H200, README "On a GPU": `bvh-packet` traced camera
// rays at 0.35-0.49x and shadow and diffuse rays at 0.04-0.13x the rate of
// `bvh`).
bool packets_for_coherent_calls(const DeviceInfo& device);

// The -D options every trace program needs for this geometry.
std::vector<std::string> primitive_defines(const Geometry& geometry);

}  // namespace rtcl
