// Ray-set previews for the benchmark scenes; the rays themselves come from
// bench/support/ray_sets.hpp (shared with `rtcl bench`).
#pragma once

#include <string>

#include "bench_scenes.hpp"
#include "bench/support/ray_sets.hpp"

namespace rtcl::bench {

// A binary PPM of the primary hits (grey by the cosine to the camera, darker
// where the shadow ray is occluded, blue for misses): how the cameras and
// lights were checked. Written when $RTCL_BENCH_DUMP names a directory.
void write_preview(const std::string& path, const BenchScene& scene);

}  // namespace rtcl::bench
