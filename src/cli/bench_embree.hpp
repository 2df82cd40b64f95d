// The Embree baseline of `rtcl bench` (bench/support/embree_baseline.hpp):
// the very rays of a cell traced by Embree on host threads, timed as
// Embree's own framing has it: the traversal alone (the rays converted into
// Embree's records before it and the answers read after it, as rtcl's
// kernel time leaves out upload and read-back), and the whole with those
// conversions as the wall time. Absent, not an error, when rtcl was built
// without Embree.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "bench_report.hpp"
#include "rtcl/accel.hpp"
#include "rtcl/layouts.hpp"
#include "rtcl/geometry.hpp"

namespace rtcl::cli {

// "3.13.5", or "" when rtcl was built without Embree.
std::string embree_baseline_version(unsigned threads);

class EmbreeBaseline {
 public:
  // Builds Embree's scene of the geometry's triangles and spheres (its default, medium
  // quality build on `threads` threads; `robust`: with
  // RTC_SCENE_FLAG_ROBUST, Embree's watertight mode) `builds` times, each
  // after kBuildPause, and keeps the last (its peak memory: the figures'
  // build_peak_bytes).
  EmbreeBaseline(const Geometry& geometry, unsigned threads, bool robust, int builds);
  ~EmbreeBaseline();
  EmbreeBaseline(const EmbreeBaseline&) = delete;
  EmbreeBaseline& operator=(const EmbreeBaseline&) = delete;

  // Whether Embree traces 8-ray packets natively here (rtcIntersect8 is then measured too).
  bool has_packets() const;

  // One more build of the scene, as the constructor's, released at once:
  // its ms (`rtcl bench` pairs one with each build of a structure).
  double build_once_ms() const;

  // One warm-up trace, then `repeat` timed ones of `rays`, single rays or
  // packets of rays 8k .. 8k + 7; fills the baseline's figures (the
  // builds' among them, not its check) and returns the answers of the last
  // trace.
  std::vector<Hit> measure(Query query, bool packets, const std::vector<Ray>& rays, int repeat,
                           BenchBaseline& out) const;

  // One trace of `rays` (prepared before the clock starts): the traversal's
  // ms, as measure() times each of its traces. `rtcl bench` runs one after
  // each of a cell's launches, so that the cell's ratio compares times
  // taken in the same moments.
  double trace_ms(Query query, bool packets, const std::vector<Ray>& rays) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  const Geometry* geometry_;
  unsigned threads_;
  bool robust_;
  std::vector<double> build_ms_runs_;
  std::size_t build_peak_bytes_ = 0;  // of the last build (peak_memory.hpp)
};

}  // namespace rtcl::cli
