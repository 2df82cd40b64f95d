// What `rtcl bench` measured, and its two renderings: bench.json (every
// figure, the machine and the options, so that runs from several machines
// merge) and bench.md (one table per device). Schema: docs/cli.md, "rtcl bench".
#pragma once

#include <chrono>
#include <cstddef>
#include <string>
#include <vector>

namespace rtcl::cli {

// min / median / max of repeated measurements, in the unit the field names.
struct Spread {
  double min = 0.0, median = 0.0, max = 0.0;
};
Spread spread_of(std::vector<double> values);  // all 0 for no values

// The pause before each timed build of `rtcl bench` (a structure's and
// Embree's): longer than the threads of the step before (PoCL's, TBB's,
// rtcl's own) spin once out of work, so that none runs into the build, and
// every build starts with its threads asleep, as a program's one build does.
inline constexpr std::chrono::milliseconds kBuildPause{20};
// Builds per structure and scene: --repeat, up to this many (a build of
// millions of triangles takes a second, a trace launch milliseconds).
inline constexpr int kMaxBuilds = 9;
inline int build_count(int repeat) { return repeat < kMaxBuilds ? repeat : kMaxBuilds; }

struct BenchCell {
  std::size_t device = 0;  // index into BenchRun::devices
  std::string scene, accel, rays, query;  // rays: primary | shadow | diffuse; query: closest | any
  std::string precision;                  // fast | robust | exact
  std::size_t ray_count = 0;
  double build_ms = 0.0;       // host build (AccelStats::build_ms): the median of build_ms_runs
  std::vector<double> build_ms_runs;  // each build of the structure, after kBuildPause
  // Embree's build of the scene right after each of those (after its own
  // pause), when the run has the baseline: the build ratio is taken from
  // these, as a trace ratio from embree_paired_ms.
  std::vector<double> embree_build_ms_runs;
  // make_accel's wall time less build_ms: the upload and the closest-hit
  // program's build. Programs are cached per process and device, so a
  // structure's first cell carries the build (the BVH's: rays_ms of the
  // first scene), and PoCL's own cache (POCL_CACHE_DIR) shortens it on
  // later runs.
  double setup_ms = 0.0;
  double first_launch_ms = 0.0;  // the warm-up launch, wall: includes the query's program build at its first use
  std::size_t device_bytes = 0;
  std::size_t primitives = 0;
  // How far the process's peak resident memory rose during the last build
  // (make_accel: build, flatten and upload; peak_memory.hpp); 0 where the
  // kernel cannot reset the peak.
  std::size_t build_peak_bytes = 0;
  std::vector<double> kernel_ms, wall_ms;  // per timed launch, in launch order
  bool profiled = false;                   // kernel_ms from OpenCL events (else the host clock)
  std::size_t checked = 0, disagreeing = 0;  // rays compared with brute force, and those that differ
  // Whether the structure traces packets of eight consecutive rays (its
  // compared with Embree's packet API, else with its single-ray API).
  bool packets = false;
  // Shadow cells: rays (packets) a work-item traces in turn, each first
  // tested against the previous one's occluder (Accel::occluder_run); 1
  // for closest-hit cells and structures without occluder runs.
  std::size_t occluder_run = 1;
  // Of the timed calls, how many sorted the rays on the device first
  // (Coherence::scattered, Accel::last_call_sorted): their kernel time
  // spans the sort and the trace. `sorted`: more than half of them.
  int sorted_runs = 0;
  bool sorted = false;
  // Embree's traversal of the same rays right after each timed launch (its
  // API as `packets` says), when the run has the baseline and Embree traces
  // such packets: the cell's ratio is taken from these.
  std::vector<double> embree_paired_ms;
};

// Embree's figures for one scene and ray set (bench_embree.hpp).
struct BenchBaseline {
  std::string scene, rays, api;  // api: rtcIntersect1 | rtcOccluded1 | rtcIntersect8 | rtcOccluded8
  bool packets = false;
  unsigned threads = 0;
  std::size_t ray_count = 0;
  double build_ms = 0.0;   // rtcCommitScene and geometry setup, wall: the median of build_ms_runs
  std::vector<double> build_ms_runs;  // each build of the scene, after kBuildPause
  std::size_t bytes = 0;   // Embree's memory after the build (its memory monitor)
  std::size_t build_peak_bytes = 0;  // the rise of peak resident memory during the last build (as BenchCell's)
  std::vector<double> trace_ms, wall_ms;  // per timed trace: the traversal alone; with the ray and answer conversions
  std::size_t checked = 0, disagreeing = 0;
};

struct BenchDevice {
  std::size_t index = 0;  // list_devices() index
  std::string name, platform, type, version, driver;
};

struct BenchSceneInfo {
  std::string name;
  std::size_t triangles = 0, spheres = 0;
  double load_ms = 0.0;
  // Ray generation on the first device: the BVH that spawns the secondary
  // rays (its build and closest-hit program build included) and brute
  // force's reference hits.
  double rays_ms = 0.0;
  std::size_t primary = 0, shadow = 0, diffuse = 0;  // rays in each set
};

// `--instances N` (bench_instances.hpp): N instances of one mesh in an
// rtcl::Scene against Embree's instanced scene (one child scene, N
// RTC_GEOMETRY_TYPE_INSTANCE geometries), on the run's first device.
struct BenchInstances {
  std::string mesh;  // the instanced mesh's scene name (bunny)
  std::size_t instances = 0, ray_count = 0, device_bytes = 0;
  double bottom_commit_ms = 0.0;      // rtcl's first commit: the bottom level and a first top level
  std::vector<double> commit_ms;      // top-level commits after every instance moved (CommitStats::build_ms)
  std::vector<double> trace_ms;       // Scene::trace of the forest camera's primary rays, wall until the kernel ends
  double embree_child_ms = 0.0;       // the child scene's rtcCommitScene, timed apart
  std::vector<double> embree_setup_ms, embree_commit_ms;  // the instance geometries' setup; rtcCommitScene
  std::vector<double> embree_trace_ms;  // rtcIntersect1 of the same rays, right after each of rtcl's traces
  unsigned embree_threads = 0;
  std::size_t agreeing = 0;  // rays with the same instance and triangle in both, or a miss in both
};

struct BenchRun {
  std::string rtcl_version, rtcl_commit, host_cpu, started_utc, pocl_cache_dir;
  unsigned host_threads = 0;
  int size = 0, repeat = 0;
  std::size_t check_rays = 0;
  std::string precision;     // the structures' level: fast | robust | exact
  std::string embree_flags;  // Embree's scene flags: none (its default) | robust
  std::string diffuse_sort = "measured";  // the diffuse calls' ScatteredSort (BenchOptions::diffuse_sort)
  std::vector<std::string> accels, scenes, ray_kinds;
  std::vector<BenchDevice> devices;
  std::vector<BenchSceneInfo> scene_info;
  std::vector<BenchCell> cells;
  std::string embree_version;  // "" when the run has no Embree baseline
  std::vector<BenchBaseline> embree;
  std::vector<BenchInstances> instances;  // empty unless --instances was given
};

// The Embree baseline a cell is compared with (same scene and rays, packets
// against packets), or null.
const BenchBaseline* baseline_for(const BenchRun& run, const BenchCell& cell);

std::string bench_json(const BenchRun& run);
std::string bench_markdown(const BenchRun& run);

}  // namespace rtcl::cli
