// `rtcl bench --instances N`: N instances of the bunny placed as the
// forest of bench/support/forest.hpp in an rtcl::Scene, against Embree's
// instanced scene of the same placements (bench/support/
// embree_instances.hpp): the top-level commit after every instance moved
// against rtcCommitScene of the instance scene (each side's bottom level
// committed once before, timed apart), and the primary rays of the forest
// camera (--size x --size) through both, Embree's trace right after each
// of rtcl's.
#pragma once

#include <string>

#include "bench_matrix.hpp"
#include "bench_report.hpp"
#include "rtcl/device.hpp"

namespace rtcl::cli {

// `embree_threads` 0: without Embree's side. The bunny comes from
// `scenes_dir` (bench_scenes.hpp's "bunny").
BenchInstances bench_instances(const Device& device, const BenchOptions& options, const std::string& scenes_dir,
                               unsigned embree_threads);

}  // namespace rtcl::cli
