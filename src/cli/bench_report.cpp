#include "bench_report.hpp"

#include <algorithm>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "rates.hpp"

namespace rtcl::cli {

Spread spread_of(std::vector<double> values) {
  if (values.empty()) return {};
  std::sort(values.begin(), values.end());
  std::size_t n = values.size();
  double median = n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  return {values.front(), median, values.back()};
}

namespace {

using nlohmann::json;

json spread_json(const Spread& s) { return {{"min", s.min}, {"median", s.median}, {"max", s.max}}; }

// Mrays/s for each of min / median / max time: the fastest rate from the
// shortest time. A time of 0 (a timer too coarse for a tiny launch) gives 0.
Spread rate_of(std::size_t rays, const Spread& ms) {
  auto rate = [rays](double t) { return t > 0.0 ? static_cast<double>(rays) / (t * 1e3) : 0.0; };
  return {rate(ms.max), rate(ms.median), rate(ms.min)};
}

// "median (min - max)" of a rate in Mrays/s, each with three significant
// digits at least (rates.hpp).
std::string rate_text(const Spread& rate) {
  return mrays_text(rate.median) + " (" + mrays_text(rate.min) + " - " + mrays_text(rate.max) + ")";
}

// Embree's traversal rate for a cell: from the traces paired with its
// launches when it has them, else from the baseline's own traces.
Spread embree_rate(const BenchCell& c, const BenchBaseline& b) {
  return c.embree_paired_ms.empty() ? rate_of(b.ray_count, spread_of(b.trace_ms))
                                    : rate_of(c.ray_count, spread_of(c.embree_paired_ms));
}

// The cell's build against Embree's builds paired with it: the ratio of the
// medians (rtcl / Embree: below 1, rtcl builds faster); 0 without them.
double build_ratio(const BenchCell& c) {
  const double embree = spread_of(c.embree_build_ms_runs).median;
  return embree > 0.0 ? c.build_ms / embree : 0.0;
}

// The cell against its Embree baseline: Embree's traversal rate and the
// ratio of the medians (rtcl kernel rate / Embree traversal rate).
json embree_json(const BenchCell& c, const BenchBaseline* b) {
  if (!b) return nullptr;
  Spread embree = embree_rate(c, *b);
  Spread rtcl = rate_of(c.ray_count, spread_of(c.kernel_ms));
  return {{"api", b->api},
          {"threads", b->threads},
          {"paired", !c.embree_paired_ms.empty()},
          {"trace_ms_runs", c.embree_paired_ms.empty() ? b->trace_ms : c.embree_paired_ms},
          {"mrays_per_s", spread_json(embree)},
          {"ratio", embree.median > 0.0 ? rtcl.median / embree.median : 0.0},
          {"build_ms_runs", c.embree_build_ms_runs},
          {"build_ratio", build_ratio(c)}};
}

json baseline_json(const BenchBaseline& b) {
  Spread trace = spread_of(b.trace_ms), wall = spread_of(b.wall_ms);
  return {{"scene", b.scene},
          {"rays", b.rays},
          {"api", b.api},
          {"packets", b.packets},
          {"threads", b.threads},
          {"ray_count", b.ray_count},
          {"build_ms", b.build_ms},
          {"build_ms_runs", b.build_ms_runs},
          {"bytes", b.bytes},
          {"build_peak_bytes", b.build_peak_bytes},
          {"trace_ms", spread_json(trace)},
          {"wall_ms", spread_json(wall)},
          {"mrays_per_s", {{"trace", spread_json(rate_of(b.ray_count, trace))},
                           {"wall", spread_json(rate_of(b.ray_count, wall))}}},
          {"trace_ms_runs", b.trace_ms},
          {"wall_ms_runs", b.wall_ms},
          {"check", {{"reference", "brute"}, {"rays", b.checked}, {"disagreeing", b.disagreeing},
                     {"ok", b.disagreeing == 0}}}};
}

json cell_json(const BenchCell& c, const BenchBaseline* baseline) {
  Spread kernel = spread_of(c.kernel_ms), wall = spread_of(c.wall_ms);
  return {
      {"device", c.device},
      {"scene", c.scene},
      {"accel", c.accel},
      {"rays", c.rays},
      {"precision", c.precision},
      {"query", c.query},
      {"ray_count", c.ray_count},
      {"build_ms", c.build_ms},
      {"build_ms_runs", c.build_ms_runs},
      {"setup_ms", c.setup_ms},
      {"first_launch_ms", c.first_launch_ms},
      {"packets", c.packets},
      {"occluder_run", c.occluder_run},
      {"sorted", c.sorted},
      {"sorted_runs", c.sorted_runs},
      {"device_bytes", c.device_bytes},
      {"primitives", c.primitives},
      {"bytes_per_primitive",
       c.primitives ? static_cast<double>(c.device_bytes) / static_cast<double>(c.primitives) : 0.0},
      {"build_peak_bytes", c.build_peak_bytes},
      {"build_peak_bytes_per_primitive",
       c.primitives ? static_cast<double>(c.build_peak_bytes) / static_cast<double>(c.primitives) : 0.0},
      {"kernel_ms", spread_json(kernel)},
      {"kernel_timer", c.profiled ? "opencl-events" : "host-clock"},
      {"wall_ms", spread_json(wall)},
      {"mrays_per_s", {{"kernel", spread_json(rate_of(c.ray_count, kernel))},
                       {"wall", spread_json(rate_of(c.ray_count, wall))}}},
      {"kernel_ms_runs", c.kernel_ms},
      {"wall_ms_runs", c.wall_ms},
      {"check", {{"reference", "brute"}, {"rays", c.checked}, {"disagreeing", c.disagreeing},
                 {"ok", c.disagreeing == 0}}},
      // null without an Embree baseline
      {"embree", embree_json(c, baseline)},
  };
}

}  // namespace

const BenchBaseline* baseline_for(const BenchRun& run, const BenchCell& cell) {
  for (const BenchBaseline& b : run.embree)
    if (b.scene == cell.scene && b.rays == cell.rays && b.packets == cell.packets) return &b;
  return nullptr;
}

std::string bench_json(const BenchRun& run) {
  json devices = json::array(), scenes = json::array(), cells = json::array();
  for (const BenchDevice& d : run.devices)
    devices.push_back({{"index", d.index}, {"name", d.name}, {"platform", d.platform}, {"type", d.type},
                       {"version", d.version}, {"driver", d.driver}});
  for (const BenchSceneInfo& s : run.scene_info)
    scenes.push_back({{"name", s.name}, {"triangles", s.triangles}, {"spheres", s.spheres}, {"load_ms", s.load_ms},
                      {"rays_ms", s.rays_ms},
                      {"rays", {{"primary", s.primary}, {"shadow", s.shadow}, {"diffuse", s.diffuse}}}});
  for (const BenchCell& c : run.cells) cells.push_back(cell_json(c, baseline_for(run, c)));
  json embree = nullptr;
  if (!run.embree_version.empty()) {
    json baselines = json::array();
    for (const BenchBaseline& b : run.embree) baselines.push_back(baseline_json(b));
    embree = {{"version", run.embree_version}, {"flags", run.embree_flags}, {"baselines", baselines}};
  }
  json instances = json::array();
  for (const BenchInstances& i : run.instances) {
    json embree_part = nullptr;
    if (!i.embree_commit_ms.empty())
      embree_part = {{"threads", i.embree_threads},
                     {"child_commit_ms", i.embree_child_ms},
                     {"setup_ms", spread_json(spread_of(i.embree_setup_ms))},
                     {"commit_ms", spread_json(spread_of(i.embree_commit_ms))},
                     {"commit_ms_runs", i.embree_commit_ms},
                     {"trace_ms", spread_json(spread_of(i.embree_trace_ms))},
                     {"trace_ms_runs", i.embree_trace_ms},
                     {"agreeing", i.agreeing}};
    instances.push_back({{"mesh", i.mesh},
                         {"instances", i.instances},
                         {"rays", i.ray_count},
                         {"device_bytes", i.device_bytes},
                         {"bottom_commit_ms", i.bottom_commit_ms},
                         {"commit_ms", spread_json(spread_of(i.commit_ms))},
                         {"commit_ms_runs", i.commit_ms},
                         {"trace_ms", spread_json(spread_of(i.trace_ms))},
                         {"trace_ms_runs", i.trace_ms},
                         {"embree", embree_part}});
  }
  json out = {
      {"schema", "rtcl-bench/1"},
      {"rtcl", {{"version", run.rtcl_version}, {"commit", run.rtcl_commit}}},
      {"host", {{"cpu", run.host_cpu}, {"threads", run.host_threads}}},
      {"started_utc", run.started_utc},
      {"options", {{"size", run.size}, {"repeat", run.repeat}, {"check_rays", run.check_rays},
                   {"accel", run.accels}, {"scene", run.scenes}, {"rays", run.ray_kinds},
                   {"precision", run.precision}, {"embree_flags", run.embree_flags},
                   {"diffuse_sort", run.diffuse_sort},
                   {"pocl_cache_dir", run.pocl_cache_dir}}},
      {"devices", devices},
      {"scenes", scenes},
      {"cells", cells},
      {"embree", embree},
      {"instances", instances},
  };
  return out.dump(2) + "\n";
}

namespace {

std::string format(const char* pattern, double a, double b = 0.0, double c = 0.0) {
  char text[96];
  std::snprintf(text, sizeof text, pattern, a, b, c);
  return text;
}

const BenchCell* find_cell(const BenchRun& run, std::size_t device, const std::string& scene, const std::string& accel,
                           const std::string& rays) {
  for (const BenchCell& c : run.cells)
    if (c.device == device && c.scene == scene && c.accel == accel && c.rays == rays) return &c;
  return nullptr;
}

}  // namespace

std::string bench_markdown(const BenchRun& run) {
  std::string md = "rtcl " + run.rtcl_commit + ", " + run.host_cpu + ", " + std::to_string(run.host_threads) +
                   " threads, " + std::to_string(run.size) + "x" + std::to_string(run.size) +
                   " rays per primary set, median (min - max) Mrays/s of " + std::to_string(run.repeat) +
                   " kernel launches after a warm-up (OpenCL event times), precision " + run.precision +
                   "; build: host ms, median of " + std::to_string(build_count(run.repeat)) + " builds, each after a " +
                   std::to_string(kBuildPause.count()) +
                   " ms pause; B/prim: device bytes per primitive; peak B/prim: the rise of the process's peak "
                   "resident memory during the last build, per primitive; check: rays agreeing with brute force" +
                   (run.diffuse_sort != "never"
                        ? "; diffuse rays traced as scattered calls, sorted on the device " +
                              std::string(run.diffuse_sort == "always" ? "always"
                                                                       : "where the structure measured that faster") +
                              ": \"sorted\" cells include the sort in their time (\"sorted k/n\": k of n launches)"
                        : std::string()) +
                   (run.embree_version.empty()
                        ? std::string(".\n")
                        : "; xE: ratio to Embree " + run.embree_version +
                              (run.embree_flags == "robust" ? " (RTC_SCENE_FLAG_ROBUST)" : " (default flags)") +
                              " on the same rays (its traversal time on the host threads; packet kernels against "
                              "rtcIntersect8 / rtcOccluded8), and for the build to its default build, each paired "
                              "with one of the structure's.\n");
  for (std::size_t d = 0; d < run.devices.size(); ++d) {
    const BenchDevice& device = run.devices[d];
    md += "\n### [" + std::to_string(device.index) + "] " + device.name + " (" + device.platform + ", driver " +
          device.driver + ")\n\n| scene | structure | build ms | B/prim | peak B/prim |";
    for (const std::string& rays : run.ray_kinds) md += " " + rays + " |";
    md += " check |\n|---|---|---:|---:|---:|";
    for (std::size_t i = 0; i < run.ray_kinds.size(); ++i) md += "---:|";
    md += "---|\n";
    for (const std::string& scene : run.scenes)
      for (const std::string& accel : run.accels) {
        const BenchCell* first = nullptr;
        std::string row, check;
        std::size_t checked = 0, disagreeing = 0;
        for (const std::string& rays : run.ray_kinds) {
          const BenchCell* c = find_cell(run, d, scene, accel, rays);
          if (!c) {
            row += " - |";
            continue;
          }
          if (!first) first = c;
          Spread rate = rate_of(c->ray_count, spread_of(c->kernel_ms));
          row += " " + rate_text(rate);
          if (c->sorted_runs > 0 && c->sorted_runs == static_cast<int>(c->kernel_ms.size()))
            row += " sorted";
          else if (c->sorted_runs > 0)
            row += " sorted " + std::to_string(c->sorted_runs) + "/" + std::to_string(c->kernel_ms.size());
          if (const BenchBaseline* b = baseline_for(run, *c)) {
            Spread embree = embree_rate(*c, *b);
            if (embree.median > 0.0) row += format(" x%.2fE", rate.median / embree.median);
          }
          row += " |";
          checked += c->checked;
          disagreeing += c->disagreeing;
        }
        if (!first) continue;
        check = disagreeing == 0 ? "ok " + std::to_string(checked)
                                 : "**DISAGREES " + std::to_string(disagreeing) + "/" + std::to_string(checked) + "**";
        double per_prim = first->primitives ? static_cast<double>(first->device_bytes) /
                                                  static_cast<double>(first->primitives)
                                            : 0.0;
        std::string build = format(" %.1f", first->build_ms);
        if (build_ratio(*first) > 0.0) build += format(" x%.2fE", build_ratio(*first));
        double peak_per_prim = first->primitives ? static_cast<double>(first->build_peak_bytes) /
                                                       static_cast<double>(first->primitives)
                                                 : 0.0;
        md += "| " + scene + " | " + accel + " |" + build + " |" + format(" %.1f |", per_prim) +
              format(" %.1f |", peak_per_prim) + row + " " + check + " |\n";
      }
  }
  if (!run.embree.empty()) {
    md += "\n### Embree " + run.embree_version + " on the host (" + std::to_string(run.embree.front().threads) +
          " threads)\n\n| scene | API | build ms | B/prim | peak B/prim |";
    for (const std::string& rays : run.ray_kinds) md += " " + rays + " |";
    md += " check |\n|---|---|---:|---:|---:|";
    for (std::size_t i = 0; i < run.ray_kinds.size(); ++i) md += "---:|";
    md += "---|\n";
    for (const std::string& scene : run.scenes)
      for (bool packets : {false, true}) {
        std::string row, api;
        const BenchBaseline* first = nullptr;
        std::size_t checked = 0, disagreeing = 0;
        for (const std::string& rays : run.ray_kinds) {
          const BenchBaseline* b = nullptr;
          for (const BenchBaseline& x : run.embree)
            if (x.scene == scene && x.rays == rays && x.packets == packets) b = &x;
          if (!b) {
            row += " - |";
            continue;
          }
          if (!first) first = b;
          if (api.find(b->api) == std::string::npos) api += (api.empty() ? "" : " / ") + b->api;
          Spread rate = rate_of(b->ray_count, spread_of(b->trace_ms));
          row += " " + rate_text(rate) + " |";
          checked += b->checked;
          disagreeing += b->disagreeing;
        }
        if (!first) continue;
        const BenchSceneInfo* info = nullptr;
        for (const BenchSceneInfo& s : run.scene_info)
          if (s.name == scene) info = &s;
        std::size_t prims = info ? info->triangles + info->spheres : 0;
        double per_prim = prims ? static_cast<double>(first->bytes) / static_cast<double>(prims) : 0.0;
        std::string check = disagreeing == 0 ? "ok " + std::to_string(checked)
                                             : "**DISAGREES " + std::to_string(disagreeing) + "/" +
                                                   std::to_string(checked) + "**";
        double peak_per_prim = prims ? static_cast<double>(first->build_peak_bytes) / static_cast<double>(prims) : 0.0;
        md += "| " + scene + " | " + api + " |" + format(" %.1f |", first->build_ms) + format(" %.1f |", per_prim) +
              format(" %.1f |", peak_per_prim) + row + " " + check + " |\n";
      }
  }
  for (const BenchInstances& i : run.instances) {
    const bool embree = !i.embree_commit_ms.empty();
    const double commit = spread_of(i.commit_ms).median, trace = spread_of(i.trace_ms).median;
    md += "\n### " + std::to_string(i.instances) + " instances of " + i.mesh + " (rtcl::Scene" +
          (embree ? " against Embree's instanced scene, " + std::to_string(i.embree_threads) + " threads" : "") +
          ")\n\n| | rtcl | Embree | rtcl / Embree |\n|---|---:|---:|---:|\n";
    const double embree_commit = embree ? spread_of(i.embree_commit_ms).median : 0.0;
    const double embree_trace = embree ? spread_of(i.embree_trace_ms).median : 0.0;
    const auto ratio = [](double a, double b) { return b > 0.0 ? format(" %.2f |", a / b) : std::string(" - |"); };
    md += "| top-level commit ms |" + format(" %.2f |", commit) +
          (embree ? format(" %.2f |", embree_commit) : std::string(" - |")) + ratio(commit, embree_commit) + "\n";
    md += "| primary rays Mrays/s |" + format(" %.1f |", static_cast<double>(i.ray_count) / (trace * 1e3)) +
          (embree ? format(" %.1f |", static_cast<double>(i.ray_count) / (embree_trace * 1e3)) : std::string(" - |")) +
          ratio(embree_trace, trace) + "\n";
    md += format("\nrtcl: first commit (bottom level) %.1f ms, ", i.bottom_commit_ms) +
          format("%.1f MB on the device", static_cast<double>(i.device_bytes) / 1e6);
    if (embree)
      md += format("; Embree: child scene commit %.1f ms, ", i.embree_child_ms) +
            format("instance setup %.2f ms; ", spread_of(i.embree_setup_ms).median) +
            format("same instance and triangle on %.2f%% of rays",
                   100.0 * static_cast<double>(i.agreeing) / static_cast<double>(std::max<std::size_t>(i.ray_count, 1)));
    md += ".\n";
  }
  return md;
}

}  // namespace rtcl::cli
