// An Accel's mutable state behind its public header (internal): the trace
// kernels built so far, the scattered calls' sort and its choice, the
// extra queries' kernels, and the lock that makes the structure's calls
// thread-safe.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/accel/ray_sort.hpp"
#include "rtcl/accel/sort_choice.hpp"

namespace rtcl {

struct Accel::State {
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
  // A scattered call whose device time is still to be recorded.
  struct PendingCall {
    bool sorted = false;
    cl::Event first, done;
    std::size_t ray_count = 0;
  };

  State(TraceKernels incoherent_kernels, ScatteredSort policy)
      : incoherent{std::move(incoherent_kernels), {}, {}}, sort_choices{SortChoice(policy), SortChoice(policy)} {}

  KernelSet& set_for(Coherence coherence);
  QueryKernel& kernel_for(KernelSet& set, Query query, const Device& device,
                          const std::vector<std::string>& structure_defines);
  // Whether this call of the coherence sorts: asks the query's SortChoice,
  // after recording the query's pending measured call if it has finished.
  bool sort_this_call(Coherence coherence, Query query);
  void record_pending(Query query);

  // Held by every call that enqueues work or changes this state.
  std::mutex mutex;
  KernelSet incoherent;
  std::optional<KernelSet> coherent, scattered;
  std::unique_ptr<RaySort> sort;  // at the first call that sorts
  cl::Event first_event;
  bool last_sorted = false;
  // Per query (closest, any): the choice and its call in flight.
  std::array<SortChoice, 2> sort_choices;
  std::array<std::optional<PendingCall>, 2> pending;
  // Host-array calls pack separate ray arrays here (HostBatches), kept
  // between calls.
  std::vector<unsigned char> staging;
  // Kernels of kernels/query/ by "file:kernel" (detail::AccelAccess::kernel).
  std::map<std::string, cl::Kernel> query_kernels;
};

namespace detail {

// The library's own access to a structure's internals (src/rtcl/query/).
struct AccelAccess {
  static std::mutex& mutex(const Accel& accel) { return accel.state_->mutex; }
  static bool plain_bvh8(const Accel& accel) { return accel.plain_bvh8(); }
  // Throws Error "CALL: structure NAME does not support this query
  // (supported: ...)" unless the structure is laid out as the plain 8-wide
  // BVH, which the kernels of kernels/query/ walk.
  static void require_plain_bvh8(const Accel& accel, const char* call);
  // Enqueues `kernel` over `items` work-items after `wait`, in work-groups
  // of a fixed size where the kernel allows (the global size rounded up; the
  // kernels check their counts): PoCL generates code per local size, and
  // left to choose (NULL) it picks one per global size, so each new count
  // would cost a code generation.
  static cl::Event launch(const Accel& accel, const cl::Kernel& kernel, std::size_t items,
                          const std::vector<cl::Event>& wait);
  // Staging memory of host-array calls; call with mutex(accel) held.
  static std::vector<unsigned char>& staging(const Accel& accel) { return accel.state_->staging; }
  // Kernel `kernel_name` of kernels/`file`, built with the structure's
  // defines plus `defines`, its structure arguments set from argument
  // `first_structure_arg` on (Accel::set_structure_args); built once per
  // structure, file, kernel and defines. `level`: built at that precision
  // level instead of the structure's (its options replace the structure's
  // precision_build_options), for a query that fixes its own arithmetic.
  // Call with mutex(accel) held.
  static cl::Kernel& kernel(const Accel& accel, const std::string& file, const std::string& kernel_name,
                            const std::vector<std::string>& defines, cl_uint first_structure_arg,
                            std::optional<Precision> level = std::nullopt);
  static cl::Event trace(const Accel& accel, Query query, const cl::Buffer& rays, const cl::Buffer& hits,
                         std::size_t ray_count, const std::vector<cl::Event>& wait, Coherence coherence) {
    return accel.trace_locked(query, rays, hits, ray_count, wait, coherence);
  }
};

// AccelAccess::launch on the device's queue, for kernels outside a
// structure (the two-level scene's, src/rtcl/scene/two_level.hpp).
cl::Event launch_items(const Device& device, const cl::Kernel& kernel, std::size_t items,
                       const std::vector<cl::Event>& wait);

}  // namespace detail
}  // namespace rtcl
