// `rtcl bench`: structure x scene x ray set x OpenCL device, each cell
// timed as the benchmarks time it (a warm-up launch, then --repeat kernel
// launches timed by OpenCL events, and the same launches' wall time with
// the ray upload and the hit read-back), its hits checked against brute
// force on a subset of rays; written as bench.json and bench.md (formats:
// bench_report.hpp, docs/cli.md). Every input is checked before the first
// OpenCL call.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "bench_matrix.hpp"
#include "bench_embree.hpp"
#include "bench_instances.hpp"
#include "bench_report.hpp"
#include "bench_scenes.hpp"
#include "cli_errors.hpp"
#include "rtcl/opencl.hpp"
#include "commands.hpp"
#include "distributed.hpp"
#include "flag_names.hpp"
#include "option_checks.hpp"
#include "peak_memory.hpp"
#include "progress.hpp"
#include "rtcl/accel.hpp"
#include "bench/support/ray_sets.hpp"
#include "bench/support/scenes_dir.hpp"
#include "rtcl/render/ray_order.hpp"
#include "rtcl/device.hpp"
#include "rtcl/error.hpp"
#include "rtcl/io/atomic_file.hpp"
#include "rtcl_version.hpp"

namespace rtcl::cli {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Every registered structure but brute force (O(rays x primitives); it
// answers the check), when --accel is not given.
std::vector<std::string> default_accels() {
  std::vector<std::string> out;
  for (const std::string& name : accel_names())
    if (name != "brute") out.push_back(name);
  return out;
}

// The host CPU as results from several machines need it told apart: the
// first processor's model name, its family and model numbers (one model
// name can cover several generations: "AMD EPYC" is both a Zen 3 and a
// Zen 4) and its widest x86 vector extension (PoCL's code, and with it the
// ratios to Embree, differ between AVX2 and AVX-512), e.g. "AMD EPYC
// (family 25 model 1, AVX2)".
std::string host_cpu() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line, name, family, model, flags;
  auto value = [&line] {
    std::size_t colon = line.find(':');
    std::size_t first = colon == std::string::npos ? std::string::npos : line.find_first_not_of(' ', colon + 1);
    return first == std::string::npos ? std::string() : line.substr(first);
  };
  while (std::getline(cpuinfo, line) && !line.empty()) {
    if (line.rfind("model name", 0) == 0) name = value();
    else if (line.rfind("model", 0) == 0) model = value();
    else if (line.rfind("cpu family", 0) == 0) family = value();
    else if (line.rfind("flags", 0) == 0) flags = " " + value() + " ";
  }
  if (name.empty()) return "unknown";
  std::string isa = flags.find(" avx512f ") != std::string::npos ? "AVX-512"
                    : flags.find(" avx2 ") != std::string::npos  ? "AVX2"
                                                                  : "";
  std::string detail = family.empty() ? "" : "family " + family + " model " + model;
  if (!isa.empty()) detail += (detail.empty() ? "" : ", ") + isa;
  return detail.empty() ? name : name + " (" + detail + ")";
}

std::string utc_now() {
  std::time_t now = std::time(nullptr);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return text;
}

}  // namespace

// A scene's three ray sets, generated once (on the first device) and traced
// unchanged by every structure on every device, with brute force's answers
// for every k-th ray.
struct SceneRays {
  std::vector<Ray> sets[3];  // primary, shadow, diffuse
  std::vector<std::size_t> checked[3];  // indices of the checked rays
  std::vector<Hit> reference[3];        // brute force's hits for them
};
namespace {

constexpr const char* kind_names[3] = {"primary", "shadow", "diffuse"};
Query kind_query(int kind) { return kind == 1 ? Query::any : Query::closest; }

std::vector<Hit> trace_once(const Accel& accel, Query query, std::span<const Ray> rays) {
  std::vector<Hit> hits(rays.size());
  if (rays.empty()) return hits;
  const Device& device = accel.device();
  cl::Buffer ray_buffer = device.upload(rays.data(), rays.size_bytes(), "benchmark rays");
  cl::Buffer hit_buffer = device.allocate(hits.size() * sizeof(Hit), "benchmark hits", CL_MEM_WRITE_ONLY);
  with_cl_errors([&] {
    std::vector<cl::Event> wait{accel.trace(query, ray_buffer, hit_buffer, rays.size())};
    device.queue().enqueueReadBuffer(hit_buffer, CL_TRUE, 0, hits.size() * sizeof(Hit), hits.data(), &wait);
  });
  return hits;
}

SceneRays make_rays(const Device& device, const LoadedBenchScene& scene, int size, std::size_t check_rays) {
  SceneRays out;
  {
    std::vector<Ray> rows = bench::primary_rays(scene.camera, size, size);
    auto side = static_cast<std::uint32_t>(size);
    out.sets[0] = gather<Ray>(rows, packet_tile_order(side, side));
  }
  // The primary hits that spawn the secondary rays: the BVH's (the check
  // below tests them against brute force like every other cell).
  std::vector<std::string> names = accel_names();
  bool bvh = std::find(names.begin(), names.end(), "bvh") != names.end();
  std::unique_ptr<Accel> spawner = make_accel(device, bvh ? "bvh" : "brute", scene.geometry);
  std::vector<Hit> primary_hits = trace_once(*spawner, Query::closest, out.sets[0]);
  bench::SecondaryRays secondary = bench::secondary_rays(scene.geometry, out.sets[0], primary_hits, scene.light);
  out.sets[1] = std::move(secondary.shadow);
  out.sets[2] = std::move(secondary.diffuse);
  std::unique_ptr<Accel> brute = make_accel(device, "brute", scene.geometry);
  for (int k = 0; k < 3; ++k) {
    std::size_t n = out.sets[k].size();
    std::size_t stride = check_rays == 0 ? n + 1 : std::max<std::size_t>(1, (n + check_rays - 1) / check_rays);
    std::vector<Ray> subset;
    for (std::size_t i = 0; i < n; i += stride) {
      out.checked[k].push_back(i);
      subset.push_back(out.sets[k][i]);
    }
    out.reference[k] = trace_once(*brute, kind_query(k), subset);
  }
  return out;
}

// Agreement with brute force: same hit / miss and, for closest hits, the
// same primitive or a t within a relative 1e-3 (another triangle at the
// same distance, e.g. across a shared edge).
std::size_t disagreeing(const std::vector<Hit>& hits, const SceneRays& rays, int kind) {
  std::size_t bad = 0;
  for (std::size_t j = 0; j < rays.checked[kind].size(); ++j) {
    const Hit &a = hits[rays.checked[kind][j]], &b = rays.reference[kind][j];
    bool hit_a = a.prim >= 0, hit_b = b.prim >= 0;
    if (hit_a != hit_b) ++bad;
    else if (hit_a && kind_query(kind) == Query::closest && a.prim != b.prim && std::abs(a.t - b.t) > 1e-3f * std::abs(b.t))
      ++bad;
  }
  return bad;
}

// One cell: a warm-up launch, then `repeat` launches, each uploading the
// rays, tracing and reading the hits back (wall) with the kernel's own time
// from its profiling event.
void measure(const Accel& accel, const SceneRays& rays, int kind, Coherence coherence, int repeat,
             const EmbreeBaseline* embree, BenchCell& cell) {
  const std::vector<Ray>& set = rays.sets[kind];
  cell.ray_count = set.size();
  if (set.empty()) return;
  const Device& device = accel.device();
  Query query = kind_query(kind);
  std::vector<Hit> hits(set.size());
  cl::Buffer ray_buffer = device.upload(set.data(), set.size() * sizeof(Ray), "benchmark rays");
  cl::Buffer hit_buffer = device.allocate(hits.size() * sizeof(Hit), "benchmark hits", CL_MEM_WRITE_ONLY);
  cell.profiled = device.profiling();
  with_cl_errors([&] {
    Clock::time_point start = Clock::now();
    accel.trace(query, ray_buffer, hit_buffer, set.size(), {}, coherence).wait();
    cell.first_launch_ms = ms_since(start);
    // A scattered call that may sort measures both ways before the timed
    // calls (SortChoice: sorted calls, then unsorted ones).
    for (int w = 0; coherence == Coherence::scattered && !accel.sort_choice_settled(query) && w < 16; ++w)
      accel.trace(query, ray_buffer, hit_buffer, set.size(), {}, coherence).wait();
    for (int r = 0; r < repeat; ++r) {
      start = Clock::now();
      cl::Event written;
      device.queue().enqueueWriteBuffer(ray_buffer, CL_FALSE, 0, set.size() * sizeof(Ray), set.data(), nullptr,
                                        &written);
      cl::Event done = accel.trace(query, ray_buffer, hit_buffer, set.size(), {written}, coherence);
      std::vector<cl::Event> wait{done};
      device.queue().enqueueReadBuffer(hit_buffer, CL_TRUE, 0, hits.size() * sizeof(Hit), hits.data(), &wait);
      cell.wall_ms.push_back(ms_since(start));
      if (accel.last_call_sorted()) ++cell.sorted_runs;
      double kernel = cell.wall_ms.back();
      if (cell.profiled) kernel = accel.last_call_ms(done);
      cell.kernel_ms.push_back(kernel);
      if (embree) cell.embree_paired_ms.push_back(embree->trace_ms(query, cell.packets, set));
    }
  });
  cell.sorted = 2 * cell.sorted_runs > repeat;
  cell.checked = rays.checked[kind].size();
  cell.disagreeing = disagreeing(hits, rays, kind);
}

}  // namespace

BenchMatrix check_bench_inputs(const BenchOptions& options, bool create_output) {
  BenchMatrix m;
  m.accels = options.accel.empty() ? default_accels() : split_spec_list(options.accel);
  for (const std::string& a : m.accels) {
    if (a.empty()) throw UsageError("--accel " + options.accel + ": empty structure name in the list");
    parse_accel_flag(a);  // unknown structure or option: "--accel TEXT: ..."
  }
  std::string scenes_dir = options.scenes_dir.empty() ? bench::scenes_dir_from_env() : options.scenes_dir;
  for (const std::string& s : split_spec_list(options.scene)) m.scenes.push_back(parse_bench_scene(s, scenes_dir));
  m.scenes_dir = scenes_dir;
  if (options.instances > 0) {
    try {
      parse_bench_scene("bunny", scenes_dir);
    } catch (const std::exception& e) {
      throw UsageError("--instances " + std::to_string(options.instances) + ": the instanced mesh: " + e.what());
    }
  }
  for (const std::string& r : split_spec_list(options.rays)) {
    auto k = std::find(std::begin(kind_names), std::end(kind_names), r);
    if (k == std::end(kind_names))
      throw UsageError("--rays " + options.rays + ": unknown ray set '" + r + "' (known: primary, shadow, diffuse)");
    m.kinds.push_back(static_cast<int>(k - std::begin(kind_names)));
  }
  m.precision = parse_precision_flag(options.precision);
  if (options.diffuse_sort == "measured")
    m.diffuse_sort = ScatteredSort::measured;
  else if (options.diffuse_sort == "always")
    m.diffuse_sort = ScatteredSort::always;
  else if (options.diffuse_sort == "never")
    m.diffuse_sort = ScatteredSort::never;
  else
    throw UsageError("--diffuse-sort " + options.diffuse_sort + ": unknown (known: measured, always, never)");
  m.json_path = options.output + "/bench.json";
  m.md_path = options.output + "/bench.md";
  if (create_output) {
    std::error_code error;
    std::filesystem::create_directories(options.output, error);
    if (error) throw Error("--output " + options.output + ": cannot create the directory: " + error.message());
    check_writable(m.json_path);
    check_writable(m.md_path);
  }
  // A cache of its own, so that no other program's kernels are timed or
  // evicted; compile time shows in setup_ms / first_launch_ms only.
  if (const char* cache = std::getenv("POCL_CACHE_DIR"); !cache || !*cache) {
    std::string dir = std::filesystem::absolute(options.output + "/pocl-cache").string();
    setenv("POCL_CACHE_DIR", dir.c_str(), 1);
  }
  return m;
}

BenchRun bench_run_header(const BenchOptions& options, const BenchMatrix& m) {
  BenchRun run;
  run.pocl_cache_dir = std::getenv("POCL_CACHE_DIR");
  run.rtcl_version = RTCL_VERSION;
  run.rtcl_commit = RTCL_GIT_DESCRIBE;
  run.host_cpu = host_cpu();
  run.host_threads = std::max(1u, std::thread::hardware_concurrency());
  run.started_utc = utc_now();
  run.size = options.size;
  run.repeat = options.repeat;
  run.check_rays = static_cast<std::size_t>(options.check_rays);
  run.precision = std::string(precision_name(m.precision));
  run.embree_flags = options.embree_robust ? "robust" : "none";
  run.diffuse_sort = options.diffuse_sort;
  run.accels = m.accels;
  for (const BenchSceneSpec& s : m.scenes) run.scenes.push_back(s.text);
  for (int k : m.kinds) run.ray_kinds.push_back(kind_names[k]);
  return run;
}

BenchDevice describe_device(const Device& device) {
  const DeviceInfo& info = device.info();
  std::string driver = with_cl_errors([&] { return device.device().getInfo<CL_DRIVER_VERSION>(); });
  return {info.index, info.name, info.platform, info.type, info.version, driver};
}

PreparedScene prepare_bench_scene(const Device& device, const BenchSceneSpec& spec, const BenchOptions& options) {
  PreparedScene p;
  p.scene = load_bench_scene(spec);
  Clock::time_point rays_start = Clock::now();
  p.rays = std::make_shared<SceneRays>(
      make_rays(device, p.scene, options.size, static_cast<std::size_t>(options.check_rays)));
  const SceneRays& rays = *p.rays;
  p.info = {spec.text, p.scene.geometry.triangles.size(), p.scene.geometry.spheres.size(), p.scene.load_ms,
            ms_since(rays_start), rays.sets[0].size(), rays.sets[1].size(), rays.sets[2].size()};
  return p;
}

std::vector<BenchCell> bench_structure(const Device& device, std::size_t device_index, const PreparedScene& scene,
                                       const std::string& accel_name, const BenchMatrix& matrix, int repeat,
                                       const EmbreeBaseline* embree) {
  AccelConfig config;
  config.precision = matrix.precision;
  config.scattered_sort = matrix.diffuse_sort;
  // build_count(repeat) builds, each after kBuildPause and each followed by
  // one of Embree's (after its own pause); the cells trace the last one.
  // setup: the first's (its program builds).
  std::unique_ptr<Accel> accel;
  std::vector<double> build_ms_runs, embree_build_ms_runs;
  double setup = 0.0;
  std::size_t peak_bytes = 0;
  for (int b = 0; b < build_count(repeat); ++b) {
    accel.reset();
    std::this_thread::sleep_for(kBuildPause);
    Clock::time_point start = Clock::now();
    PeakMemory peak;
    accel = make_accel(device, accel_name, scene.scene.geometry, config);
    peak_bytes = peak.peak_extra_bytes();
    if (b == 0) setup = ms_since(start) - accel->stats().build_ms;
    build_ms_runs.push_back(accel->stats().build_ms);
    if (embree) {
      std::this_thread::sleep_for(kBuildPause);
      embree_build_ms_runs.push_back(embree->build_once_ms());
    }
  }
  const AccelStats& stats = accel->stats();
  std::vector<BenchCell> cells;
  for (int k : matrix.kinds) {
    BenchCell cell;
    cell.device = device_index;
    cell.scene = scene.info.name;
    cell.accel = accel_name;
    cell.precision = std::string(precision_name(matrix.precision));
    cell.rays = kind_names[k];
    cell.query = kind_query(k) == Query::any ? "any" : "closest";
    cell.build_ms = spread_of(build_ms_runs).median;
    cell.build_ms_runs = build_ms_runs;
    cell.embree_build_ms_runs = embree_build_ms_runs;
    cell.setup_ms = std::max(0.0, setup);
    cell.device_bytes = stats.device_bytes;
    cell.primitives = stats.primitive_count;
    cell.build_peak_bytes = peak_bytes;
    cell.packets = accel->rays_per_work_item(Coherence::incoherent) > 1;
    if (kind_query(k) == Query::any) cell.occluder_run = accel->occluder_run(Coherence::incoherent);
    Coherence coherence = k == 2 ? Coherence::scattered : Coherence::incoherent;
    measure(*accel, *scene.rays, k, coherence, repeat,
            embree && (!cell.packets || embree->has_packets()) ? embree : nullptr, cell);
    cells.push_back(std::move(cell));
  }
  return cells;
}

void write_bench_results(const BenchRun& run, const BenchMatrix& matrix) {
  std::string json = bench_json(run), md = bench_markdown(run);
  write_file_atomically(matrix.json_path, std::as_bytes(std::span(json.data(), json.size())));
  write_file_atomically(matrix.md_path, std::as_bytes(std::span(md.data(), md.size())));
  std::fputs(md.c_str(), stdout);
  std::printf("\nwritten: %s, %s\n", matrix.json_path.c_str(), matrix.md_path.c_str());
}

std::vector<BenchBaseline> bench_embree(const EmbreeBaseline& embree, const PreparedScene& scene,
                                        const std::vector<int>& kinds, int repeat) {
  std::vector<BenchBaseline> out;
  const SceneRays& rays = *scene.rays;
  for (int k : kinds)
    for (bool packets : {false, true}) {
      if (packets && !embree.has_packets()) continue;
      BenchBaseline baseline;
      baseline.scene = scene.info.name;
      baseline.rays = kind_names[k];
      std::vector<Hit> hits = embree.measure(kind_query(k), packets, rays.sets[k], repeat, baseline);
      if (!rays.sets[k].empty()) {
        baseline.checked = rays.checked[k].size();
        baseline.disagreeing = disagreeing(hits, rays, k);
      }
      out.push_back(std::move(baseline));
    }
  return out;
}

namespace {

void run_bench(const BenchOptions& options) {
  if (launcher_world_size()) {
    refuse_ranks_without_mpi("rtcl bench");
    if (mpi_supported()) return bench_distributed(options);
  }
  BenchMatrix matrix = check_bench_inputs(options, true);
  BenchRun run = bench_run_header(options, matrix);

  // --- devices ---
  std::vector<DeviceInfo> infos = list_devices();
  if (infos.empty()) throw Error("no OpenCL device found (`rtcl devices` lists them)");
  std::vector<Device> devices;
  if (const char* env = std::getenv("RTCL_DEVICE"); !options.device.empty() || (env && *env)) {
    devices.push_back(open_device_flag(options.device));  // --device, else $RTCL_DEVICE
  } else {
    for (const DeviceInfo& info : infos) devices.push_back(Device::open(std::to_string(info.index)));
  }
  for (const Device& device : devices) {
    require_precision_flag(device.info(), matrix.precision);
    run.devices.push_back(describe_device(device));
  }
  if (!options.no_embree) run.embree_version = embree_baseline_version(options.embree_threads);

  Progress progress("rtcl bench", options.quiet);
  auto step = [&progress](std::size_t done, std::size_t total, const std::string& what) {
    progress.status("[" + std::to_string(done) + "/" + std::to_string(total) + "] " + what);
  };
  std::size_t total = matrix.scenes.size() * (devices.size() * matrix.accels.size() + !run.embree_version.empty()),
              done = 0;
  for (const BenchSceneSpec& scene_spec : matrix.scenes) {
    step(done, total, scene_spec.text + ": loading, rays and brute-force references");
    PreparedScene scene = prepare_bench_scene(devices.front(), scene_spec, options);
    run.scene_info.push_back(scene.info);
    std::unique_ptr<EmbreeBaseline> embree;
    if (!run.embree_version.empty()) {
      step(done, total, scene_spec.text + " / Embree " + run.embree_version);
      embree = std::make_unique<EmbreeBaseline>(scene.scene.geometry, options.embree_threads, options.embree_robust,
                                                build_count(options.repeat));
      for (BenchBaseline& b : bench_embree(*embree, scene, matrix.kinds, options.repeat))
        run.embree.push_back(std::move(b));
      ++done;
    }
    for (std::size_t d = 0; d < devices.size(); ++d)
      for (const std::string& accel_name : matrix.accels) {
        step(done, total, scene_spec.text + " / " + accel_name + " / " + run.devices[d].name);
        for (BenchCell& cell :
             bench_structure(devices[d], d, scene, accel_name, matrix, options.repeat, embree.get()))
          run.cells.push_back(std::move(cell));
        ++done;
      }
  }
  if (options.instances > 0) {
    step(done, total, std::to_string(options.instances) + " instances of bunny / " + run.devices.front().name);
    run.instances.push_back(bench_instances(devices.front(), options, matrix.scenes_dir,
                                            run.embree_version.empty() ? 0u : options.embree_threads));
  }
  progress.clear();
  write_bench_results(run, matrix);
}

}  // namespace

void add_bench_command(CLI::App& app) {
  auto options = std::make_shared<BenchOptions>();
  CLI::App* cmd = app.add_subcommand(
      "bench", "Benchmark structures x scenes x ray sets x OpenCL devices; write bench.json and bench.md");
  cmd->add_option("--accel", options->accel,
                  "structures, comma-separated, each with build options as NAME:key=value,... (default: every "
                  "registered structure but brute)");
  cmd->add_option("--scene", options->scene,
                  "scenes, comma-separated: " + bench_scene_names() +
                      " (the mesh scenes need --scenes-dir or $RTCL_SCENES_DIR)")
      ->capture_default_str();
  cmd->add_option("--rays", options->rays, "ray sets, comma-separated: primary, shadow, diffuse")
      ->capture_default_str();
  add_device_option(*cmd, options->device, "$RTCL_DEVICE, else every device");
  cmd->add_option("--size", options->size, "image side in pixels: size x size primary rays")
      ->check(integer_in(1, 16384))
      ->capture_default_str();
  cmd->add_option("--repeat", options->repeat,
                  "timed launches per cell, after one warm-up launch; builds per structure and scene (at most 9)")
      ->check(integer_in(1, 10000))
      ->capture_default_str();
  cmd->add_option("--check-rays", options->check_rays,
                  "rays per set (every k-th) compared with brute force; 0: none")
      ->check(integer_in(0, 1 << 20))
      ->capture_default_str();
  cmd->add_option("--precision", options->precision,
                  "every structure's precision level: fast, robust or exact (docs/precision.md)")
      ->capture_default_str()
      ->check(one_of(precision_names(), "precision level"));
  cmd->add_flag("--no-embree", options->no_embree,
               "leave out the Embree baseline (present when rtcl was built with Embree)");
  cmd->add_flag("--embree-robust", options->embree_robust,
               "build Embree's scenes with RTC_SCENE_FLAG_ROBUST (its watertight mode) instead of its default "
               "flags: the baseline for --precision robust or exact like for like");
  cmd->add_option("--diffuse-sort", options->diffuse_sort,
                  "the diffuse rays are traced as scattered calls, which on a CPU device structures with a "
                  "single-ray kernel may sort first (their cells' times then include the sort; docs/cli.md): "
                  "measured (where their calls measured it faster), always or never; Embree traces them as they "
                  "come")
      ->capture_default_str()
      ->check(one_of({"measured", "always", "never"}, "sort policy"));
  cmd->add_option("--embree-threads", options->embree_threads, "host threads Embree traces and builds on")
      ->check(integer_in(1, 1024))
      ->capture_default_str();
  cmd->add_option("--instances", options->instances,
                  "also N instances of the bunny in an rtcl::Scene against Embree's instanced scene: the "
                  "top-level commit and the primary rays of a camera over them (first device; 0: none)")
      ->check(integer_in(0, 10000000))
      ->capture_default_str();
  cmd->add_option("--scenes-dir", options->scenes_dir,
                  "directory of the shared meshes (default: $RTCL_SCENES_DIR; no other default)");
  cmd->add_option("-o,--output", options->output, "directory for bench.json and bench.md (created if missing)")
      ->capture_default_str();
  add_quiet_flag(*cmd, options->quiet);
  cmd->callback([options] { run_bench(*options); });
}

}  // namespace rtcl::cli
