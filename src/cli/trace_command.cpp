// `rtcl trace MESH RAYS -o HITS`: one query for every ray of a ray file
// against a mesh, answers written to a hit file (formats: rtcl/io/ray_file.hpp).
// Order of work: cheap argument checks first, then the mesh and the rays, and
// only then the device, so that bad input is reported before any OpenCL
// start-up. The hit file is written atomically at the very end.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "accel_option.hpp"
#include "commands.hpp"
#include "flag_names.hpp"
#include "option_checks.hpp"
#include "progress.hpp"
#include "rates.hpp"
#include "rtcl/accel.hpp"
#include "rtcl/device.hpp"
#include "rtcl/error.hpp"
#include "rtcl/io/atomic_file.hpp"
#include "rtcl/io/ray_file.hpp"
#include "rtcl/scene/mesh_io.hpp"

namespace rtcl::cli {

namespace {

struct TraceOptions {
  std::string mesh, rays, hits, accel, device;
  std::string precision = "robust";
  bool any = false;
  bool coherent = false;
  bool scattered = false;
  bool quiet = false;
  int repeat = 1;  // timed launches; above 1, after warm-up launches (trace_on_device)
};

using Clock = std::chrono::steady_clock;

double elapsed_ms(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct TraceResult {
  std::vector<double> trace_ms;  // per timed launch, ascending
  bool profiled = false;         // from OpenCL event times, not the host clock
  int sorted_launches = 0;       // timed launches that sorted the rays first (Coherence::scattered)
};

// `repeat` timed launches of the same query (after one untimed warm-up
// launch, which absorbs PoCL's code generation, when repeat > 1; for
// scattered calls that may sort, until both ways are measured, as `rtcl
// bench` warms up);
// the hits are those of the last.
TraceResult trace_on_device(const Accel& accel, const std::vector<Ray>& rays, std::vector<Hit>& hits, Query query,
                            Coherence coherence, const std::string& rays_path, int repeat, Progress& progress) {
  TraceResult result;
  if (rays.empty()) return result;
  const Device& device = accel.device();
  std::string ray_what = "ray buffer for " + rays_path, hit_what = "hit buffer for " + rays_path;
  cl::Buffer ray_buffer = device.upload(rays.data(), rays.size() * sizeof(Ray), ray_what.c_str());
  cl::Buffer hit_buffer = device.allocate(hits.size() * sizeof(Hit), hit_what.c_str(), CL_MEM_WRITE_ONLY);
  with_cl_errors([&] {
    if (repeat > 1) progress.status("warm-up launch");
    if (repeat > 1) accel.trace(query, ray_buffer, hit_buffer, rays.size(), {}, coherence).wait();
    for (int w = 0; repeat > 1 && coherence == Coherence::scattered && !accel.sort_choice_settled(query) && w < 16; ++w)
      accel.trace(query, ray_buffer, hit_buffer, rays.size(), {}, coherence).wait();
    result.profiled = device.profiling();
    for (int r = 0; r < repeat; ++r) {
      progress.status(repeat > 1 ? "launch " + std::to_string(r + 1) + " of " + std::to_string(repeat) : "tracing");
      Clock::time_point start = Clock::now();
      cl::Event done = accel.trace(query, ray_buffer, hit_buffer, rays.size(), {}, coherence);
      done.wait();
      double ms = elapsed_ms(start);
      if (result.profiled) ms = accel.last_call_ms(done);
      result.trace_ms.push_back(ms);
      if (accel.last_call_sorted()) ++result.sorted_launches;
    }
    std::sort(result.trace_ms.begin(), result.trace_ms.end());
    device.queue().enqueueReadBuffer(hit_buffer, CL_TRUE, 0, hits.size() * sizeof(Hit), hits.data());
  });
  return result;
}

void run_trace(const TraceOptions& options) {
  std::string accel_name = accel_or_default(options.accel);
  parse_accel_flag(accel_name);  // name and options checked before any work
  AccelConfig config;
  config.precision = parse_precision_flag(options.precision);
  check_writable(options.hits);
  Progress progress("rtcl trace", options.quiet);

  progress.status("loading " + options.mesh);
  Clock::time_point load_start = Clock::now();
  LoadedMesh mesh = load_mesh(options.mesh);
  GeometryReport report = validate(mesh.geometry);
  double load_ms = elapsed_ms(load_start);
  progress.clear();
  for (const std::string& note : mesh.notes) std::fprintf(stderr, "rtcl: note: %s\n", note.c_str());
  if (report.zero_area_triangles > 0)
    std::fprintf(stderr, "rtcl: note: %s: %zu zero-area triangle%s skipped (no ray can hit them; ids unchanged)\n",
                 options.mesh.c_str(), report.zero_area_triangles, report.zero_area_triangles == 1 ? "" : "s");
  progress.status("reading " + options.rays);
  std::vector<Ray> rays = read_rays(options.rays);

  progress.status("opening the device");
  Device device = open_device_flag(options.device);
  const DeviceInfo& info = device.info();
  require_precision_flag(info, config.precision);
  progress.clear();
  std::printf("device: [%zu] %s (%s)\n", info.index, info.name.c_str(), info.platform.c_str());
  std::printf("mesh:   %s: %zu triangles, %zu vertices, %zu objects, loaded in %.1f ms\n", options.mesh.c_str(),
              mesh.geometry.triangles.size(), mesh.geometry.vertices.size(), mesh.objects.size(), load_ms);
  std::printf("rays:   %s: %zu rays\n", options.rays.c_str(), rays.size());
  std::fflush(stdout);

  // A ray set the device cannot hold is refused before anything is uploaded.
  device.check_fits(rays.size() * sizeof(Ray), "ray buffer for " + options.rays);
  device.check_fits(rays.size() * sizeof(Hit), "hit buffer for " + options.rays);

  progress.status("building " + accel_name);
  Clock::time_point build_start = Clock::now();
  std::unique_ptr<Accel> accel = make_accel(device, accel_name, mesh.geometry, config);
  progress.clear();
  double setup_ms = elapsed_ms(build_start);
  const AccelStats& stats = accel->stats();
  std::printf(
      "accel:  %s (%s precision): built in %.1f ms on the host (%.1f ms with kernel build and upload), %.1f MiB on "
      "the device\n",
      accel->name().c_str(), std::string(precision_name(config.precision)).c_str(), stats.build_ms, setup_ms, static_cast<double>(stats.device_bytes) / 1048576.0);

  Query query = options.any ? Query::any : Query::closest;
  Coherence coherence = options.coherent    ? Coherence::coherent
                        : options.scattered ? Coherence::scattered
                                            : Coherence::incoherent;
  std::vector<Hit> hits(rays.size());
  TraceResult traced = trace_on_device(*accel, rays, hits, query, coherence, options.rays, options.repeat, progress);
  progress.clear();
  const char* kind = options.any ? "any hit (occlusion)" : "closest hit";
  std::size_t per_item = accel->rays_per_work_item(coherence);
  std::string traversal = per_item == 1 ? "one ray per work-item" : std::to_string(per_item) + "-ray packets";
  if (std::size_t launches = traced.trace_ms.size(); traced.sorted_launches > 0)
    traversal = (traced.sorted_launches == static_cast<int>(launches)
                     ? std::string("sorted on the device")
                     : "sorted on the device in " + std::to_string(traced.sorted_launches) + " of " +
                           std::to_string(launches) + " launches (the faster as measured)") +
                ", then " + traversal;
  if (std::size_t run = accel->occluder_run(coherence); options.any && run > 1)
    traversal += " in runs of " + std::to_string(run) + ", each tested first against the previous one's occluder";
  if (rays.empty()) {
    std::printf("trace:  %s: no rays\n", kind);
  } else if (traced.trace_ms.size() == 1) {
    double ms = traced.trace_ms[0];
    std::printf("trace:  %s, %s: %.3f ms (%s), %s Mrays/s\n", kind, traversal.c_str(), ms,
                traced.profiled ? "OpenCL event profiling" : "host clock", mrays_text(double(rays.size()), ms).c_str());
  } else {
    const std::vector<double>& ms = traced.trace_ms;
    double median = ms.size() % 2 ? ms[ms.size() / 2] : 0.5 * (ms[ms.size() / 2 - 1] + ms[ms.size() / 2]);
    std::printf(
        "trace:  %s, %s: min %.3f / median %.3f / max %.3f ms over %zu warm launches (%s), %s / %s / %s "
        "Mrays/s\n",
        kind, traversal.c_str(), ms.front(), median, ms.back(), ms.size(),
        traced.profiled ? "OpenCL event profiling" : "host clock", mrays_text(double(rays.size()), ms.back()).c_str(),
        mrays_text(double(rays.size()), median).c_str(), mrays_text(double(rays.size()), ms.front()).c_str());
  }
  std::size_t hit_count = std::count_if(hits.begin(), hits.end(), [](const Hit& h) { return h.prim >= 0; });
  progress.status("writing " + options.hits);
  write_hits(options.hits, hits);
  progress.clear();
  std::printf("hits:   %s: %zu of %zu rays hit\n", options.hits.c_str(), hit_count, hits.size());
}

}  // namespace

void add_trace_command(CLI::App& app) {
  auto options = std::make_shared<TraceOptions>();
  CLI::App* cmd = app.add_subcommand("trace", "Trace every ray of a ray file against a mesh; write a hit file");
  cmd->add_option("MESH", options->mesh, "mesh file: .obj (with .mtl), .ply or .stl")->required();
  cmd->add_option("RAYS", options->rays,
                  "ray file: 32 bytes per ray, little-endian float32 ox oy oz dx dy dz tmin tmax, no header")
      ->required();
  cmd->add_option("-o,--output", options->hits,
                  "hit file to write: 16 bytes per ray, float32 t u v + int32 prim (miss: t=inf, prim=-1)")
      ->required();
  add_accel_option(*cmd, options->accel);
  cmd->add_option("--precision", options->precision,
                  "fast | robust | exact: Moller-Trumbore and fast math / watertight (default) / watertight plus "
                  "double-precision re-tests (docs/precision.md)")
      ->capture_default_str()
      ->check(one_of(precision_names(), "precision level"));
  add_device_option(*cmd, options->device, "$RTCL_DEVICE, else device 0");
  cmd->add_option("--repeat", options->repeat,
                  "launch the query N times after one warm-up launch and print the min / median / max kernel time "
                  "(as the benchmarks measure it); the hit file holds the last launch's answers")
      ->check(integer_in(1, 1000000))
      ->capture_default_str();
  cmd->add_flag("--any", options->any, "occlusion query: report any hit in [tmin, tmax], not the closest");
  cmd->add_flag("--coherent", options->coherent,
                "the rays come in coherent packets: each consecutive group of 8 (rays 0-7, 8-15, ...) has nearby "
                "origins and similar directions, e.g. camera rays in 8x8 screen-tile order or shadow rays towards "
                "one light in pixel order. On a CPU device, structures with a packet kernel (bvh, bvh-ploc, kdtree) "
                "then trace 8 rays per work-item: faster for such rays, slower for scattered ones; the closest t is "
                "the same (on an exact tie another primitive may be reported). Other devices trace one ray per "
                "work-item either way (faster there)");
  cmd->add_flag("--scattered", options->scattered,
                "the rays are many unrelated bounces (diffuse or glossy rays from hits in pixel order): on a CPU "
                "device, structures with a single-ray kernel may sort them on the device by origin cell and "
                "direction octant first: the first launch sorts, the next does not, later ones take the way "
                "measured faster, and a sorted launch's time includes the sort (docs/cli.md). The hits are the same")
      ->excludes("--coherent");
  add_quiet_flag(*cmd, options->quiet);
  cmd->callback([options] { run_trace(*options); });
}

}  // namespace rtcl::cli
