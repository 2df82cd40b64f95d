// The one main() of rtcl_bench. Benchmarks register per scene through
// add_scene_hook (bench_scenes.hpp) or with Google Benchmark's own macros;
// no other file may define main().
//
// Before any OpenCL call it points PoCL's kernel cache at a dedicated
// directory (POCL_CACHE_DIR, unless already set) so that benchmark runs
// neither pollute nor depend on the user's cache.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "bench_scenes.hpp"

#ifdef RTCL_HAVE_EMBREE
#include "bench/support/embree_baseline.hpp"
#endif

int main(int argc, char** argv) {
  setenv("POCL_CACHE_DIR", RTCL_BENCH_POCL_CACHE, /*overwrite=*/0);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;

  using namespace rtcl::bench;
  try {
    image_size(), brute_ray_limit(), host_threads();  // a malformed $RTCL_BENCH_* fails here, once
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rtcl_bench: %s\n", e.what());
    return 1;
  }
  try {
    const auto& info = bench_device().info();
    benchmark::AddCustomContext("rtcl_device", info.platform + " / " + info.name + " (" +
                                                   std::to_string(info.compute_units) + " compute units)");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rtcl_bench: %s\n(the rtcl benchmarks will report this error)\n", e.what());
    benchmark::AddCustomContext("rtcl_device", "none");
  }
#ifdef RTCL_HAVE_EMBREE
  benchmark::AddCustomContext("embree", embree_version(host_threads()));
#else
  benchmark::AddCustomContext("embree", "not built (CMake did not find Embree 3)");
#endif
  benchmark::AddCustomContext("reference", oracle_name());
  benchmark::AddCustomContext("host_threads", std::to_string(host_threads()));
  benchmark::AddCustomContext("image_size", std::to_string(image_size()));
  benchmark::AddCustomContext("brute_rays", std::to_string(brute_ray_limit()));
  benchmark::AddCustomContext("pocl_cache_dir", std::getenv("POCL_CACHE_DIR"));

  register_scene_benchmarks();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
