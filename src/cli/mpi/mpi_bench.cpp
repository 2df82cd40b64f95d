// `mpirun -np N rtcl bench ...`: the matrix's (scene, structure) pairs are
// jobs handed out by rank 0 (job_farm.hpp); each rank measures its jobs on
// its own device (by local rank, or --device) with the rays it makes for
// the scene; rank 0 merges the cells into one bench.json and bench.md, one
// device entry per rank ("NAME [rank R on HOST]").
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>

#include "bench_matrix.hpp"
#include "cli_errors.hpp"
#include "exit_codes.hpp"
#include "mpi/job_farm.hpp"
#include "mpi/mpi_world.hpp"
#include "mpi/rank_device.hpp"
#include "rtcl/error.hpp"

namespace rtcl::cli {

namespace {

nlohmann::json cell_json(const BenchCell& c) {
  return {{"scene", c.scene},       {"accel", c.accel},         {"rays", c.rays},
          {"precision", c.precision}, {"packets", c.packets}, {"occluder_run", c.occluder_run}, {"sorted", c.sorted}, {"sorted_runs", c.sorted_runs},
          {"query", c.query},       {"ray_count", c.ray_count}, {"build_ms", c.build_ms},
          {"setup_ms", c.setup_ms}, {"first_launch_ms", c.first_launch_ms},
          {"device_bytes", c.device_bytes}, {"primitives", c.primitives},
          {"kernel_ms", c.kernel_ms}, {"wall_ms", c.wall_ms}, {"profiled", c.profiled},
          {"checked", c.checked},   {"disagreeing", c.disagreeing}};
}

BenchCell cell_of(const nlohmann::json& j, std::size_t device) {
  BenchCell c;
  c.device = device;
  c.scene = j["scene"];
  c.accel = j["accel"];
  c.rays = j["rays"];
  c.precision = j["precision"];
  c.packets = j["packets"];
  c.occluder_run = j["occluder_run"];
  c.sorted = j["sorted"];
  c.sorted_runs = j["sorted_runs"];
  c.query = j["query"];
  c.ray_count = j["ray_count"];
  c.build_ms = j["build_ms"];
  c.setup_ms = j["setup_ms"];
  c.first_launch_ms = j["first_launch_ms"];
  c.device_bytes = j["device_bytes"];
  c.primitives = j["primitives"];
  c.kernel_ms = j["kernel_ms"].get<std::vector<double>>();
  c.wall_ms = j["wall_ms"].get<std::vector<double>>();
  c.profiled = j["profiled"];
  c.checked = j["checked"];
  c.disagreeing = j["disagreeing"];
  return c;
}

nlohmann::json scene_json(const BenchSceneInfo& s) {
  return {{"name", s.name},       {"triangles", s.triangles}, {"spheres", s.spheres}, {"load_ms", s.load_ms},
          {"rays_ms", s.rays_ms}, {"primary", s.primary},     {"shadow", s.shadow},   {"diffuse", s.diffuse}};
}

BenchSceneInfo scene_of(const nlohmann::json& j) {
  return {j["name"], j["triangles"], j["spheres"], j["load_ms"], j["rays_ms"], j["primary"], j["shadow"], j["diffuse"]};
}

// Ends a rank > 0 quietly after rank 0 reported the bad input.
struct BenchStoppedByRoot {};

void run(const MpiWorld& world, const BenchOptions& options) {
  const bool root = world.rank == 0;
  // Rank 0 checks the inputs and creates the output; its verdict goes to
  // every rank so that a bad input is one error, not one per rank.
  std::optional<BenchMatrix> matrix;
  std::vector<std::byte> verdict;
  if (root) {
    try {
      matrix = check_bench_inputs(options, true);
      verdict = as_bytes("ok");
    } catch (...) {
      verdict = as_bytes("failed");
      broadcast_bytes(verdict, 0);
      throw;
    }
  }
  broadcast_bytes(verdict, 0);
  if (as_text(verdict) != "ok") throw BenchStoppedByRoot{};
  if (!root) matrix = check_bench_inputs(options, false);
  const BenchMatrix& m = *matrix;

  std::unique_ptr<Device> device;
  std::optional<PreparedScene> scene;  // the last scene this rank prepared
  std::size_t scene_index = 0;
  JobSetup setup = [&]() -> nlohmann::json {
    device = std::make_unique<Device>(open_rank_device(options.device, world.local_rank));
    BenchDevice d = describe_device(*device);
    return {{"device", d.name},
            {"bench_device",
             {{"index", d.index}, {"platform", d.platform}, {"type", d.type}, {"version", d.version},
              {"driver", d.driver}}}};
  };
  // Job j: scene j / accels, structure j % accels (scene-major, so a rank
  // taking consecutive jobs reuses its rays).
  JobRun job = [&](std::size_t j) -> std::vector<std::byte> {
    std::size_t s = j / m.accels.size(), a = j % m.accels.size();
    if (!scene || scene_index != s) {
      scene.reset();
      scene = prepare_bench_scene(*device, m.scenes.at(s), options);
      scene_index = s;
    }
    nlohmann::json out{{"scene", scene_json(scene->info)}, {"cells", nlohmann::json::array()}};
    for (const BenchCell& c : bench_structure(*device, 0, *scene, m.accels[a], m, options.repeat))
      out["cells"].push_back(cell_json(c));
    return as_bytes(out.dump());
  };
  if (!root) {
    work_jobs(world, setup, job);
    return;
  }

  BenchRun run = bench_run_header(options, m);
  std::vector<long> device_of_rank(world.size, -1);
  std::vector<nlohmann::json> results;
  std::vector<int> result_rank;
  std::vector<std::size_t> order(m.scenes.size() * m.accels.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::size_t done = 0;
  std::vector<RankOutcome> outcomes =
      serve_jobs(world, order, setup, job, [&](int rank, std::size_t, std::span<const std::byte> bytes) {
        results.push_back(nlohmann::json::parse(as_text(bytes)));
        result_rank.push_back(rank);
        std::fprintf(stderr, "rtcl bench: [%zu/%zu] from rank %d\n", ++done, order.size(), rank);
      });
  for (int r = 0; r < world.size; ++r) {
    const nlohmann::json& rep = outcomes[r].report;
    if (rep.is_null() || outcomes[r].jobs == 0) continue;
    const nlohmann::json& d = rep["bench_device"];
    device_of_rank[r] = static_cast<long>(run.devices.size());
    run.devices.push_back({d["index"], rep["device"].get<std::string>() + " [rank " + std::to_string(r) + " on " +
                                           rep.value("host", std::string("?")) + "]",
                           d["platform"], d["type"], d["version"], d["driver"]});
  }
  for (std::size_t i = 0; i < results.size(); ++i) {
    const nlohmann::json& res = results[i];
    BenchSceneInfo info = scene_of(res["scene"]);
    // The first rank's ray generation for a scene stands for the scene.
    if (std::none_of(run.scene_info.begin(), run.scene_info.end(),
                     [&](const BenchSceneInfo& s) { return s.name == info.name; }))
      run.scene_info.push_back(info);
    for (const nlohmann::json& c : res["cells"])
      run.cells.push_back(cell_of(c, static_cast<std::size_t>(device_of_rank[result_rank[i]])));
  }
  // The single-process order: scene, then device, then structure, then ray set.
  auto position = [](const std::vector<std::string>& list, const std::string& v) {
    return std::find(list.begin(), list.end(), v) - list.begin();
  };
  std::stable_sort(run.scene_info.begin(), run.scene_info.end(), [&](const BenchSceneInfo& a, const BenchSceneInfo& b) {
    return position(run.scenes, a.name) < position(run.scenes, b.name);
  });
  std::stable_sort(run.cells.begin(), run.cells.end(), [&](const BenchCell& a, const BenchCell& b) {
    auto key = [&](const BenchCell& c) {
      return std::make_tuple(position(run.scenes, c.scene), c.device, position(run.accels, c.accel),
                             position(run.ray_kinds, c.rays));
    };
    return key(a) < key(b);
  });
  write_bench_results(run, m);
}

}  // namespace

void bench_distributed(const BenchOptions& options) {
  bool stopped = false;
  {
    MpiWorld world;
    try {
      run(world, options);
    } catch (const BenchStoppedByRoot&) {
      stopped = true;
    } catch (const UsageError&) {
      throw;
    } catch (const std::exception& e) {
      if (world.size == 1) throw;
      throw Error("rank " + std::to_string(world.rank) + " (host " + world.host + "): " + e.what());
    }
  }
  if (stopped) std::exit(static_cast<int>(ExitCode::failed));  // after MPI_Finalize; rank 0 said why
}

}  // namespace rtcl::cli
