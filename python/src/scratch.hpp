// Host arrays a query call converts into and the library answers into,
// kept between calls: a fresh array of 4 KiB pages costs a page fault per
// page at its first touch (on a virtual machine about 100 ms per 1M rays'
// records, as long as the trace itself), so calls lease arrays from a pool
// that keeps them. Calls run chunk by chunk (pipeline), so that a leased
// set stays small and the conversions of one chunk overlap the device work
// of the next.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "rtcl/default_init_allocator.hpp"
#include "rtcl/queries.hpp"

namespace rtcl::python {

// Rays or points per library call when a call is split: enough that a
// call's fixed costs stay small, few enough that a leased set stays small.
inline constexpr std::size_t kChunk = std::size_t{1} << 18;
// The first and the last chunk of a split call: their conversions overlap
// nothing, so they are kept short enough to run on the calling thread alone
// (below for_parts' share per thread: no pooled thread is woken, which
// would then spin for its next job on a core the device's threads use).
inline constexpr std::size_t kEdgeChunk = std::size_t{1} << 14;
// From the first chunk up to kChunk, and from kChunk down to the last, each
// chunk is at most this many times its neighbour: the helper's conversions
// of a chunk (under a tenth of the device's time per ray on the bunny's
// camera rays, by `perf`) then end before the device ends its neighbour,
// and the device never waits for them.
inline constexpr std::size_t kRampFactor = 4;

// Not zeroed when grown, and advised for huge pages (rtcl/huge_pages.hpp).
template <class T>
using HostArray = std::vector<T, DefaultInitAllocator<T>>;

struct Scratch {
  HostArray<Ray> rays;
  HostArray<Hit> hits;
  HostArray<std::uint32_t> ids;  // rtcl::Scene's instance ids of the hits
  HostArray<float> xyz;
  HostArray<PointHit> point_hits;

  // The first n elements of an array, grown to hold them.
  template <class T>
  static std::span<T> first(HostArray<T>& array, std::size_t n) {
    if (array.size() < n) array.resize(n);
    return std::span<T>(array.data(), n);
  }
};

// One Scratch for the lifetime of the lease, from the process-wide pool
// (thread-safe: each concurrent call holds its own).
class ScratchLease {
 public:
  ScratchLease();
  ~ScratchLease();
  ScratchLease(const ScratchLease&) = delete;
  ScratchLease& operator=(const ScratchLease&) = delete;
  Scratch& operator*() { return *scratch_; }
  Scratch* operator->() { return scratch_.get(); }

 private:
  std::unique_ptr<Scratch> scratch_;
};

// Runs [0, count) chunk by chunk (one chunk below 3 kEdgeChunk; else
// chunks growing from kEdgeChunk by kRampFactor up to kChunk, equal chunks
// of at most kChunk, and the same ramp down to kEdgeChunk) through pack(slot, first, n, parallel), run(slot, first, n) and
// unpack(slot, first, n, parallel), where slot (0 or 1) names one of two
// sets of scratch arrays. run(k) on the calling thread (the device work)
// overlaps unpack(k - 1) and pack(k + 1) on a helper thread of the call,
// which sleeps between them (parallel = false); the first pack and the last
// unpack, overlapping nothing, may use every host thread
// (rtcl/parallel.hpp). A job's exception is rethrown after the chunk's jobs
// have returned (run's before the helper's).
void pipeline(std::size_t count, const std::function<void(int, std::size_t, std::size_t, bool)>& pack,
              const std::function<void(int, std::size_t, std::size_t)>& run,
              const std::function<void(int, std::size_t, std::size_t, bool)>& unpack);

}  // namespace rtcl::python
