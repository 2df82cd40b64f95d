// The pieces of `rtcl bench` that the single-process run (bench_command.cpp)
// and the run split over MPI ranks (mpi/mpi_bench.cpp) share: the checked
// inputs, one structure's cells on one device, the run's header and the
// written result.
#pragma once

#include <algorithm>
#include <memory>
#include <thread>
#include <string>
#include <vector>

#include "bench_embree.hpp"
#include "bench_report.hpp"
#include "bench_scenes.hpp"
#include "rtcl/precision.hpp"
#include "rtcl/accel/sort_choice.hpp"
#include "rtcl/device.hpp"

namespace rtcl::cli {

struct BenchOptions {
  std::string accel, scene = "bunny", rays = "primary,shadow,diffuse", device, scenes_dir, output = "bench-results";
  int size = 512;
  int repeat = 5;
  int check_rays = 256;
  std::string precision = "robust";  // every structure's level (AccelConfig::precision)
  bool quiet = false;  // no progress display
  bool no_embree = false;  // without Embree built in, there is no baseline either way
  bool embree_robust = false;  // Embree's scenes with RTC_SCENE_FLAG_ROBUST
  // Diffuse rays are traced as Coherence::scattered calls; whether they
  // sort (AccelConfig::scattered_sort): measured, always or never.
  std::string diffuse_sort = "measured";
  unsigned embree_threads = std::max(1u, std::thread::hardware_concurrency());
  int instances = 0;  // --instances: bunny instances of the instanced-scene section; 0: none
};

// Every input of a run, checked before the first OpenCL call.
struct BenchMatrix {
  std::vector<std::string> accels;
  std::vector<BenchSceneSpec> scenes;
  std::vector<int> kinds;  // 0 primary, 1 shadow, 2 diffuse
  std::string scenes_dir;  // --scenes-dir, else $RTCL_SCENES_DIR
  Precision precision = Precision::robust;
  ScatteredSort diffuse_sort = ScatteredSort::measured;  // BenchOptions::diffuse_sort
  std::string json_path, md_path;
};

// Throws UsageError / Error naming the option. `create_output`: creates the
// output directory and checks the two files can be written (rank 0 only,
// under MPI); also points POCL_CACHE_DIR at the output when unset.
BenchMatrix check_bench_inputs(const BenchOptions& options, bool create_output);

// The run's description (versions, host, options, matrix) without devices
// or cells.
BenchRun bench_run_header(const BenchOptions& options, const BenchMatrix& matrix);

BenchDevice describe_device(const Device& device);

// A scene's ray sets and their brute-force answers (made on one device).
struct SceneRays;
struct PreparedScene {
  LoadedBenchScene scene;
  BenchSceneInfo info;
  std::shared_ptr<SceneRays> rays;
};
PreparedScene prepare_bench_scene(const Device& device, const BenchSceneSpec& spec, const BenchOptions& options);

// One structure over one scene on one device at the matrix's precision
// level: a cell per ray kind, with `device_index` as the cell's device.
// With `embree` (the scene's baseline, else null), each timed launch is
// followed by Embree's trace of the same rays (BenchCell::embree_paired_ms).
std::vector<BenchCell> bench_structure(const Device& device, std::size_t device_index, const PreparedScene& scene,
                                       const std::string& accel, const BenchMatrix& matrix, int repeat,
                                       const EmbreeBaseline* embree = nullptr);

// Embree's figures on the scene's ray sets (single rays, and 8-ray packets
// where Embree traces them natively), checked like the cells; needs rtcl
// built with Embree (embree_baseline_version() not empty).
std::vector<BenchBaseline> bench_embree(const EmbreeBaseline& embree, const PreparedScene& scene,
                                        const std::vector<int>& kinds, int repeat);

// bench.json and bench.md, each written whole or not at all; the table on
// stdout.
void write_bench_results(const BenchRun& run, const BenchMatrix& matrix);

// The matrix split over MPI ranks (docs/cli.md, "Under mpirun").
void bench_distributed(const BenchOptions& options);

}  // namespace rtcl::cli
