// `mpirun -np N rtcl render ...`: rank 0 reads the scene (or every rank
// does, --scene-from each), broadcasts it with the image settings, and hands
// out image tiles on demand (job_farm.hpp); every rank, rank 0 included in
// a second thread, builds its own structure and renders tiles; rank 0
// pastes them into the image and writes it once every tile is in.
#include <mpi.h>
#include <signal.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <mutex>

#include "distributed.hpp"
#include "exit_codes.hpp"
#include "flag_names.hpp"
#include "mpi/fault_injection.hpp"
#include "mpi/job_farm.hpp"
#include "mpi/mpi_world.hpp"
#include "mpi/rank_device.hpp"
#include "render_units.hpp"
#include "rtcl/error.hpp"
#include "rtcl/render/image.hpp"
#include "rtcl/render/tiles.hpp"
#include "rtcl/scene/default_scene.hpp"
#include "rtcl/scene/scene_bytes.hpp"
#include "rtcl/scene/scene_file.hpp"

namespace rtcl::cli {

bool mpi_supported() { return true; }

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Ends a rank > 0 quietly after rank 0 reported the error that stopped the
// run (rank 0's message is the one the user sees).
struct StoppedByRoot : std::exception {
  const char* what() const noexcept override { return "stopped: rank 0 failed before rendering"; }
};

// What rank 0 decided, sent to every rank: the plan, the tiles and the
// images (units) to render.
nlohmann::json plan_header(const RenderPlan& plan, const RenderOptions& o, const RenderUnits& units) {
  const RenderSettings& s = plan.settings;
  nlohmann::json list = nlohmann::json::array();
  for (const RenderUnit& u : units.units) list.push_back({{"output", u.output}, {"frame", u.frame}, {"spp", u.spp}});
  return {{"ok", true},
          {"unit_kind", static_cast<int>(units.kind)},
          {"frame_time", units.frame_time},
          {"units", list},
          {"width", s.width},
          {"height", s.height},
          {"spp", s.spp},
          {"depth", s.max_depth},
          {"min_weight", s.min_weight},
          {"batch", s.batch_pixels},
          {"sampler", static_cast<std::uint32_t>(s.sampler)},
          {"seed", s.seed},
          {"filter", static_cast<std::uint32_t>(s.filter)},
          {"light_samples", s.light_samples},
          {"precision", std::string(precision_name(plan.config.precision))},
          {"accel", plan.accel},
          {"tile", o.tile},
          {"tile_order", o.tile_order}};
}

RenderUnits units_of(const nlohmann::json& h) {
  RenderUnits units;
  units.kind = static_cast<UnitKind>(h["unit_kind"].get<int>());
  units.frame_time = h["frame_time"];
  for (const nlohmann::json& u : h["units"])
    units.units.push_back({u["output"].get<std::string>(), u["frame"].get<std::int64_t>(), u["spp"].get<std::uint32_t>()});
  return units;
}

RenderPlan plan_of(const nlohmann::json& h) {
  RenderPlan plan;
  plan.settings.width = h["width"];
  plan.settings.height = h["height"];
  plan.settings.spp = h["spp"];
  plan.settings.max_depth = h["depth"];
  plan.settings.min_weight = h["min_weight"].get<float>();
  plan.settings.batch_pixels = h["batch"];
  plan.settings.sampler = static_cast<Sampler>(h["sampler"].get<std::uint32_t>());
  plan.settings.seed = h["seed"];
  plan.settings.filter = static_cast<Filter>(h["filter"].get<std::uint32_t>());
  plan.settings.light_samples = h["light_samples"];
  plan.config.precision = parse_precision(h["precision"].get<std::string>());
  plan.accel = h["accel"];
  return plan;
}

// One tile's answer: its ray counts and stage times, then its pixels.
struct TileStats {
  std::uint64_t camera, shadow, reflection, refraction;
  double render_ms, camera_trace_ms, secondary_trace_ms, shadow_trace_ms, generate_ms, shade_ms, compact_ms,
      accumulate_ms;
  std::uint64_t peak_queue, generations;
};

std::vector<std::byte> tile_bytes(const Image& part, const RenderStats& st) {
  TileStats t{st.rays.camera,       st.rays.shadow,        st.rays.reflection,  st.rays.refraction,
              st.render_ms,         st.camera_trace_ms,    st.secondary_trace_ms, st.shadow_trace_ms,
              st.generate_ms,       st.shade_ms,           st.compact_ms,       st.accumulate_ms,
              st.peak_queue,        st.generations};
  std::vector<std::byte> out(sizeof t + part.rgb.size() * sizeof(float));
  std::memcpy(out.data(), &t, sizeof t);
  std::memcpy(out.data() + sizeof t, part.rgb.data(), part.rgb.size() * sizeof(float));
  return out;
}

void add(RenderStats& sum, const TileStats& t) {
  sum.rays.camera += t.camera;
  sum.rays.shadow += t.shadow;
  sum.rays.reflection += t.reflection;
  sum.rays.refraction += t.refraction;
  sum.camera_trace_ms += t.camera_trace_ms;
  sum.secondary_trace_ms += t.secondary_trace_ms;
  sum.shadow_trace_ms += t.shadow_trace_ms;
  sum.generate_ms += t.generate_ms;
  sum.shade_ms += t.shade_ms;
  sum.compact_ms += t.compact_ms;
  sum.accumulate_ms += t.accumulate_ms;
  sum.peak_queue = std::max<std::size_t>(sum.peak_queue, t.peak_queue);
  sum.generations += static_cast<std::uint32_t>(t.generations);
}

// Everything a rank renders with, built by its job setup.
struct RankRenderer {
  std::unique_ptr<Device> device;
  std::unique_ptr<Renderer> renderer;
  std::size_t unit = 0;  // the unit (animation frame) `renderer` renders
  std::size_t tiles_run = 0;
};

void run(MpiWorld& world, const RenderOptions& o) {
  const bool root = world.rank == 0;
  const bool broadcast = o.scene_from == "root";
  Fault fault = fault_from_environment();

  // --- rank 0 decides; the decision (or its failure) goes to every rank ---
  SceneDescription scene;
  RenderPlan plan;
  RenderUnits units;
  std::string header_text;
  double scene_ms = 0.0;
  if (root) {
    nlohmann::json header;
    try {
      if (!o.accel.empty()) parse_accel_flag(o.accel);
      Clock::time_point start = Clock::now();
      scene = load_render_scene(o);
      scene_ms = ms_since(start);
      plan = plan_render(o, scene);
      units = plan_units(o, scene, plan.settings.spp);  // checks the output paths
      image_tiles(plan.settings.width, plan.settings.height, o.tile, parse_tile_order(o.tile_order));  // checks
      header = plan_header(plan, o, units);
    } catch (const std::exception& e) {
      header = {{"ok", false}};
      header_text = header.dump();
      std::vector<std::byte> bytes = as_bytes(header_text);
      broadcast_bytes(bytes, 0);
      throw;
    }
    header_text = header.dump();
  }
  std::vector<std::byte> header_bytes = as_bytes(header_text);
  broadcast_bytes(header_bytes, 0);
  nlohmann::json header = nlohmann::json::parse(as_text(header_bytes));
  if (!header["ok"].get<bool>()) throw StoppedByRoot();
  if (!root) {
    plan = plan_of(header);
    units = units_of(header);
  }
  const std::uint32_t tile = header["tile"];
  std::vector<ImageRegion> tiles = image_tiles(plan.settings.width, plan.settings.height, tile,
                                               parse_tile_order(header["tile_order"].get<std::string>()));

  // --- the scene: broadcast from rank 0, or read by every rank ---
  double broadcast_ms = 0.0;
  std::vector<std::byte> bytes;  // decoded in the setup below, where a failure is the rank's alone
  if (broadcast) {
    if (root) bytes = scene_to_bytes(scene);
    check_mpi(MPI_Barrier(MPI_COMM_WORLD), "MPI_Barrier");  // time the broadcast alone
    Clock::time_point start = Clock::now();
    broadcast_bytes(bytes, 0);
    broadcast_ms = ms_since(start);
  }
  const std::size_t scene_bytes = bytes.size();

  // --- every rank's setup and tiles ---
  RankRenderer mine;
  JobSetup setup = [&]() -> nlohmann::json {
    nlohmann::json report;
    if (broadcast && !root) {
      scene = scene_from_bytes(bytes, "the scene broadcast by rank 0");
      bytes = {};
    }
    if (!broadcast && !root) {
      Clock::time_point start = Clock::now();
      scene = read_render_scene(o);
      scene_ms = ms_since(start);
    }
    report["scene_ms"] = broadcast ? broadcast_ms : scene_ms;
    mine.device = std::make_unique<Device>(open_rank_device(o.device, world.local_rank));
    report["device"] = mine.device->info().name;
    require_precision_flag(mine.device->info(), plan.config.precision);
    Clock::time_point start = Clock::now();
    mine.renderer = naming_accel_flag(o.accel, [&] {
      return std::make_unique<Renderer>(*mine.device, unit_scene(scene, units, units.units.front()), plan.accel,
                                        plan.config);
    });
    // Warm-up: PoCL generates a kernel's code at its first launch; one
    // tile rendered and dropped keeps that out of the tiles' times.
    mine.renderer->render(plan.settings, tiles.front());
    report["setup_ms"] = ms_since(start);
    report["build_ms"] = mine.renderer->build_ms();
    return report;
  };
  // Job j is tile j % tiles of unit j / tiles: the units' tiles in unit
  // order, so a rank mostly stays on one frame's renderer.
  JobRun render_tile = [&](std::size_t job) -> std::vector<std::byte> {
    bool faulty = fault.rank == world.rank && mine.tiles_run++ == 0;
    if (faulty && fault.kind == FaultKind::kill) ::raise(SIGKILL);
    const std::size_t u = job / tiles.size();
    if (units.kind == UnitKind::frames && u != mine.unit) {
      mine.renderer.reset();
      mine.renderer = naming_accel_flag(o.accel, [&] {
        return std::make_unique<Renderer>(*mine.device, unit_scene(scene, units, units.units.at(u)), plan.accel,
                                          plan.config);
      });
      mine.unit = u;
    }
    RenderSettings settings = plan.settings;
    settings.spp = units.units.at(u).spp;
    Image part = mine.renderer->render(settings, tiles.at(job % tiles.size()));
    if (faulty && fault.kind == FaultKind::error)
      throw Error("injected fault (RTCL_MPI_FAULT=error:" + std::to_string(world.rank) + ") after its first tile");
    return tile_bytes(part, mine.renderer->stats());
  };
  if (!root) {
    work_jobs(world, setup, render_tile);
    return;
  }

  // Each unit's image, written as soon as its last tile is in.
  std::vector<Image> images(units.units.size());
  std::vector<std::size_t> missing(units.units.size(), tiles.size());
  RenderStats total;
  std::vector<double> render_ms(world.size, 0.0);  // the ranks' own time in Renderer::render
  std::vector<double> slowest_ms(world.size, 0.0);  // their slowest tile
  std::vector<std::size_t> order(tiles.size() * units.units.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  FarmTimes times;
  std::vector<RankOutcome> outcomes = serve_jobs(
      world, order, setup, render_tile,
      [&](int rank, std::size_t job, std::span<const std::byte> bytes) {
        const std::size_t u = job / tiles.size();
        const ImageRegion& r = tiles.at(job % tiles.size());
        TileStats t;
        if (bytes.size() != sizeof t + std::size_t(r.width) * r.height * 3 * sizeof(float))
          throw Error("MPI: tile " + std::to_string(job) + " came back with " + std::to_string(bytes.size()) + " bytes");
        std::memcpy(&t, bytes.data(), sizeof t);
        Image part{r.width, r.height, std::vector<float>(std::size_t(r.width) * r.height * 3)};
        std::memcpy(part.rgb.data(), bytes.data() + sizeof t, part.rgb.size() * sizeof(float));
        Image& image = images.at(u);
        if (image.rgb.empty())
          image = Image{plan.settings.width, plan.settings.height,
                        std::vector<float>(std::size_t(plan.settings.width) * plan.settings.height * 3, 0.0f)};
        paste(image, r, part);
        if (--missing[u] == 0) {
          write_image(units.units[u].output, image);
          image = Image{};
        }
        add(total, t);
        render_ms[rank] += t.render_ms;
        slowest_ms[rank] = std::max(slowest_ms[rank], t.render_ms);
      },
      &times);
  total.render_ms = times.span_ms;
  for (std::size_t u = 0; u < units.units.size(); ++u)
    if (missing[u] != 0) throw Error("internal: " + units.units[u].output + " misses " + std::to_string(missing[u]) + " tiles");

  std::size_t failed = 0;
  for (const RankOutcome& r : outcomes) failed += !r.failure.empty();
  std::string devices = std::to_string(world.size) + " MPI ranks, " + std::to_string(tiles.size()) + " tiles of " +
                        std::to_string(tile) + " px" +
                        (units.units.size() > 1 ? " in each of " + std::to_string(units.units.size()) + " images" : "") +
                        (failed ? ", " + std::to_string(failed) + " failed" : "");
  print_render_summary(o, plan, devices, total,
                       mine.renderer ? mine.renderer->defines() : std::vector<std::string>{});
  if (broadcast)
    std::printf("rtcl render: scene %.3f MiB broadcast to %d ranks\n", scene_bytes / 1048576.0, world.size);
  std::printf("rtcl render: rank 0 served %zu tiles from other ranks in %.1f ms (%.3f ms per tile)\n",
              times.remote_results, times.serve_ms,
              times.remote_results ? times.serve_ms / times.remote_results : 0.0);
  for (std::size_t r = 0; r < outcomes.size(); ++r) {
    const RankOutcome& out = outcomes[r];
    const nlohmann::json& rep = out.report;
    if (rep.is_null()) {
      std::printf("rtcl render: rank %zu: failed while setting up: %s\n", r, out.failure.c_str());
      continue;
    }
    std::printf("rtcl render: rank %zu (host %s, device %s): scene %s %.1f ms, renderer and warm-up %.1f ms (structure built in "
                "%.1f ms), %zu tiles: rendering %.1f ms (slowest tile %.1f ms), handed out to returned %.1f ms%s%s\n",
                r, rep.value("host", std::string("?")).c_str(), rep.value("device", std::string("?")).c_str(),
                broadcast ? "broadcast" : "read", rep.value("scene_ms", 0.0), rep.value("setup_ms", 0.0),
                rep.value("build_ms", 0.0), out.jobs, render_ms[r], slowest_ms[r], out.busy_ms,
                out.failure.empty() ? "" : ", failed: ", out.failure.c_str());
  }
}

}  // namespace

void render_distributed(const RenderOptions& o) {
  bool stopped = false;
  {
    MpiWorld world;
    try {
      run(world, o);
    } catch (const StoppedByRoot&) {
      stopped = true;
    } catch (const UsageError&) {
      throw;  // a bad command line, found by rank 0: as in one process
    } catch (const std::exception& e) {
      if (world.size == 1) throw;
      throw Error("rank " + std::to_string(world.rank) + " (host " + world.host + "): " + e.what());
    }
  }
  if (stopped) std::exit(static_cast<int>(ExitCode::failed));  // after MPI_Finalize; rank 0 said why
}

}  // namespace rtcl::cli
