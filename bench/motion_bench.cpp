// The motion BVH's two node-bound forms against each other
// (docs/rendering.md):
//   motion/<scene>/<motion>/<bounds>   kernel time of one closest-hit launch
//     over the scene's primary rays (pixel order), each ray at its own
//     uniformly random time; bounds: swept (one box per child over the
//     shutter) or interpolated (boxes at open and close, interpolated at the
//     ray's time); motion: the whole mesh translated along x by 2%, 10% or
//     50% of its bounding-box diagonal over the shutter ("shift-N"), or
//     turned by 10 degrees about the vertical axis through its centre
//     ("turn-10").
//   motion/<scene>/static/bvh          the static BVH on the same rays at shutter
//     open: what motion costs.
// Kernel time from OpenCL event profiling, manual time, after a warm-up
// launch (PoCL compiles at the first launch).
#include <benchmark/benchmark.h>

#include <memory>
#include <random>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "bench/support/timing.hpp"
#include "bench_scenes.hpp"
#include "rtcl/accel/bvh_motion.hpp"

namespace rtcl::bench {
namespace {


// The scene's geometry at shutter close for `motion`.
Geometry moved(const Geometry& open, const std::string& motion) {
  Geometry close = open;
  Aabb box = open.bounds();
  glm::dvec3 diagonal = glm::dvec3(box.extent()), centre = glm::dvec3(box.center());
  glm::dmat4 m(1.0);
  if (motion.rfind("shift-", 0) == 0)
    m = glm::translate(m, glm::dvec3(std::stod(motion.substr(6)) / 100.0 * glm::length(diagonal), 0.0, 0.0));
  else if (motion == "turn-10")
    m = glm::translate(m, centre) * glm::rotate(glm::dmat4(1.0), glm::radians(10.0), glm::dvec3(0, 1, 0)) *
        glm::translate(glm::dmat4(1.0), -centre);
  for (glm::vec3& v : close.vertices) v = glm::vec3(m * glm::dvec4(glm::dvec3(v), 1.0));
  return close;
}

void motion_benchmark(benchmark::State& state, const std::string& scene_name, const std::string& motion,
                      const std::string& bounds) {
  try {
    auto scene = bench_scene(scene_name);
    const Device& device = bench_device();
    const std::vector<Ray>& rays = scene->primary.rays;
    std::vector<float> times(rays.size());
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (float& t : times) t = unit(rng);
    cl::Buffer ray_buf = device.upload(rays.data(), rays.size() * sizeof(Ray), "rays");
    cl::Buffer time_buf = device.upload(times.data(), times.size() * sizeof(float), "ray times");
    cl::Buffer hit_buf = device.allocate(rays.size() * sizeof(Hit), "hits");
    std::unique_ptr<Accel> fixed;
    std::unique_ptr<MotionBvh> moving;
    if (bounds == "bvh") {
      fixed = make_accel(device, "bvh", scene->geometry);
    } else {
      moving = std::make_unique<MotionBvh>(device, scene->geometry, moved(scene->geometry, motion),
                                           bounds == "swept" ? MotionBounds::swept : MotionBounds::interpolated);
    }
    auto launch = [&] {
      return fixed ? fixed->trace(Query::closest, ray_buf, hit_buf, rays.size())
                   : moving->trace(Query::closest, ray_buf, RayTimes{time_buf}, hit_buf, rays.size());
    };
    launch().wait();
    for (auto _ : state) {
      cl::Event done = launch();
      done.wait();
      state.SetIterationTime(kernel_seconds(done));
    }
    std::vector<Hit> hits(rays.size());
    device.queue().enqueueReadBuffer(hit_buf, CL_TRUE, 0, hits.size() * sizeof(Hit), hits.data());
    std::size_t hit_count = 0;
    for (const Hit& h : hits) hit_count += h.prim >= 0;
    const AccelStats& stats = fixed ? fixed->stats() : moving->stats();
    state.counters["rays"] =
        benchmark::Counter(static_cast<double>(rays.size()), benchmark::Counter::kIsIterationInvariantRate);
    state.counters["hit_fraction"] = static_cast<double>(hit_count) / static_cast<double>(rays.size());
    state.counters["build_ms"] = stats.build_ms;
    state.counters["device_bytes"] = static_cast<double>(stats.device_bytes);
    state.SetLabel(device.info().name);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

[[maybe_unused]] const bool motion_registered = [] {
  for (std::string scene : {"bunny", "sibenik"}) {
    benchmark::RegisterBenchmark(("motion/" + scene + "/static/bvh").c_str(), motion_benchmark, scene, "static", "bvh")
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond);
    for (std::string motion : {"shift-2", "shift-10", "shift-50", "turn-10"})
      for (std::string bounds : {"swept", "interpolated"})
        benchmark::RegisterBenchmark(("motion/" + scene + "/" + motion + "/" + bounds).c_str(), motion_benchmark,
                                     scene, motion, bounds)
            ->UseManualTime()
            ->Unit(benchmark::kMillisecond);
  }
  return true;
}();

}  // namespace
}  // namespace rtcl::bench
