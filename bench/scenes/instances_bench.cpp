// Two-level scenes (rtcl::Scene) against the flat BVH and against Embree's
// instancing, same rays, same run (docs/scenes-and-instances.md):
//   top level   Scene::commit of N instances of the bunny (its bottom level
//               built by an earlier commit) against rtcCommitScene of a
//               scene of N RTC_GEOMETRY_TYPE_INSTANCE geometries over one
//               committed child scene (the child's commit is timed apart,
//               as rtcl's bottom level is); N = --counts;
//   identity    the bunny's primary rays through the flat `bvh`, through a
//               scene of one identity instance (the single-level path) and
//               through two levels (the identity instance and a far copy);
//   forest      --forest instances of the bunny (random turn and scale on a
//               grid), primary rays of a camera above them, through the
//               scene against Embree's instanced scene, rtcIntersect1 on 2
//               threads over rays prepared outside the timed region.
// rtcl's trace figures are of cl_mem calls until the kernel ends (no upload
// or read-back). Each figure is the median of --repeat calls after one
// warm-up call; the identity and forest figures' calls are interleaved.
//
//   rtcl_instances_bench [--scenes-dir DIR] [--size 1024] [--repeat 5] [--counts 1000,10000,100000]
//                        [--forest 10000]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "bench/support/forest.hpp"
#include "bench/support/ray_sets.hpp"
#include "bench/support/scenes_dir.hpp"
#include "bench/support/timing.hpp"
#include "rtcl/rtcl.hpp"
#include "rtcl/scene/mesh_io.hpp"
#ifdef RTCL_HAVE_EMBREE
#include "bench/support/embree_instances.hpp"
#endif

namespace {

using rtcl::bench::Clock;
using rtcl::bench::median;
using rtcl::bench::ms_since;

std::string fixed(double x, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, x);
  return text;
}

std::vector<std::size_t> split_counts(const std::string& text) {
  std::vector<std::size_t> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) out.push_back(std::stoul(item));
  return out;
}

}  // namespace

int main(int argc, char** argv) try {
  std::string scenes_dir = rtcl::bench::scenes_dir(), counts_text = "1000,10000,100000";
  int size = 1024, repeat = 5;
  std::size_t forest_count = 10000;
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw rtcl::Error(arg + ": needs a value");
      return argv[++i];
    };
    if (arg == "--scenes-dir") scenes_dir = value();
    else if (arg == "--size") size = std::stoi(value());
    else if (arg == "--repeat") repeat = std::stoi(value());
    else if (arg == "--counts") counts_text = value();
    else if (arg == "--forest") forest_count = std::stoul(value());
    else throw rtcl::Error(arg + ": unknown option (--scenes-dir, --size, --repeat, --counts, --forest)");
  }
  if (size < 8 || repeat < 1 || forest_count < 1) throw rtcl::Error("--size must be >= 8, --repeat and --forest >= 1");
  rtcl::Device device = rtcl::Device::open();
  const rtcl::Geometry bunny = rtcl::load_mesh(scenes_dir + "/stanford_bunny/bunny.obj").geometry;
  std::printf("device: %s; bunny (%zu triangles); medians of %d calls\n\n", device.info().name.c_str(),
              bunny.triangles.size(), repeat);
#ifdef RTCL_HAVE_EMBREE
  rtcl::bench::EmbreeInstances embree_scene(bunny, 2);
  std::printf("Embree child scene commit (bunny): %.1f ms\n\n", embree_scene.child_ms());
#endif

  // ---- Top-level build -------------------------------------------------------
  std::printf("| instances | rtcl commit ms | Embree setup ms | Embree commit ms | rtcl/Embree commit |\n|---|---|---|---|---|\n");
  for (std::size_t count : split_counts(counts_text)) {
    const std::vector<rtcl::Transform> placed = rtcl::bench::forest_placements(count, bunny.bounds(), 1);
    rtcl::Scene scene(device);
    rtcl::MeshId mesh = scene.add_mesh(bunny);
    std::vector<rtcl::InstanceId> ids;
    for (const rtcl::Transform& t : placed) ids.push_back(scene.add_instance(mesh, t));
    scene.commit();  // the bottom level, and a first top level
    std::vector<double> ms = rtcl::bench::top_level_commit_ms(scene, ids, placed, repeat + 1);
    ms.erase(ms.begin());  // the warm-up
    const double rtcl_ms = median(ms);
    std::string embree_setup = "-", embree_commit = "-", ratio = "-";
#ifdef RTCL_HAVE_EMBREE
    std::vector<double> setup, commit;
    for (int r = 0; r <= repeat; ++r) {
      auto [s, c] = embree_scene.place(placed);
      if (r > 0) setup.push_back(s), commit.push_back(c);
    }
    embree_setup = fixed(median(setup), 2);
    embree_commit = fixed(median(commit), 2);
    ratio = fixed(rtcl_ms / median(commit), 2);
#endif
    std::printf("| %zu | %.2f | %s | %s | %s |\n", count, rtcl_ms, embree_setup.c_str(), embree_commit.c_str(),
                ratio.c_str());
  }

  // ---- One identity instance against the flat BVH ---------------------------------
  {
    const rtcl::Aabb b = bunny.bounds();
    const glm::vec3 c = b.center(), e = b.extent();
    const float far = 100.0f * glm::length(e);
    rtcl::bench::Camera camera{c + glm::vec3(0.0f, 0.2f * e.y, 2.2f * std::max(e.x, e.y)), c, {0, 1, 0}, 45.0f};
    const std::vector<rtcl::Ray> rays = rtcl::bench::primary_rays(camera, size, size);
    const std::size_t n = rays.size();
    cl::Buffer ray_buffer = device.upload(rays.data(), n * sizeof(rtcl::Ray), "bench rays");
    cl::Buffer hit_buffer = device.allocate(n * sizeof(rtcl::Hit), "bench hits");
    auto flat = rtcl::make_accel(device, "bvh", bunny);
    rtcl::Scene single(device), two(device);
    single.add_instance(single.add_mesh(bunny));
    single.commit();
    rtcl::MeshId mesh = two.add_mesh(bunny);
    two.add_instance(mesh);
    two.add_instance(mesh, rtcl::Transform::translate(far, 0, 0));
    two.commit();
    // The three interleaved, call by call, so that a change in the machine's
    // load falls on all of them alike.
    const std::vector<std::function<void()>> calls = {
        [&] { flat->trace(rtcl::Query::closest, ray_buffer, hit_buffer, n).wait(); },
        [&] { single.trace(rtcl::Query::closest, ray_buffer, hit_buffer, n).wait(); },
        [&] { two.trace(rtcl::Query::closest, ray_buffer, hit_buffer, n).wait(); }};
    std::vector<std::vector<double>> ms(calls.size());
    for (int r = 0; r <= repeat; ++r)
      for (std::size_t c = 0; c < calls.size(); ++c) {
        auto start = Clock::now();
        calls[c]();
        if (r > 0) ms[c].push_back(ms_since(start));
      }
    const double flat_ms = median(ms[0]), single_ms = median(ms[1]), two_ms = median(ms[2]);
    const double mrays = static_cast<double>(n) * 1e-3;
    std::printf("\n%d x %d bunny primary rays (Mrays/s):\n", size, size);
    std::printf("| flat bvh | one identity instance (single level) | ratio | identity instance, two levels | ratio |\n|---|---|---|---|---|\n");
    std::printf("| %.1f | %.1f | %.3f | %.1f | %.3f |\n", mrays / flat_ms, mrays / single_ms, flat_ms / single_ms,
                mrays / two_ms, flat_ms / two_ms);
  }

  // ---- The forest --------------------------------------------------------------
  {
    const std::vector<rtcl::Transform> placed = rtcl::bench::forest_placements(forest_count, bunny.bounds(), 2);
    rtcl::Scene scene(device);
    rtcl::MeshId mesh = scene.add_mesh(bunny);
    for (const rtcl::Transform& t : placed) scene.add_instance(mesh, t);
    rtcl::CommitStats built = scene.commit();
    const rtcl::bench::Camera camera = rtcl::bench::forest_camera(forest_count, bunny.bounds());
    const std::vector<rtcl::Ray> rays = rtcl::bench::primary_rays(camera, size, size);
    const std::size_t n = rays.size();
    cl::Buffer ray_buffer = device.upload(rays.data(), n * sizeof(rtcl::Ray), "bench rays");
    cl::Buffer hit_buffer = device.allocate(n * sizeof(rtcl::Hit), "bench hits");
    const auto trace_rtcl = [&] {
      const auto start = Clock::now();
      scene.trace(rtcl::Query::closest, ray_buffer, hit_buffer, n).wait();
      return ms_since(start);
    };
    std::vector<std::uint32_t> ids(n);
    std::vector<rtcl::Hit> hits = scene.intersect(rays, ids);
    std::size_t hit_count = 0;
    for (const rtcl::Hit& h : hits) hit_count += h.prim >= 0;
    const double mrays = static_cast<double>(n) * 1e-3;
    std::printf("\nforest of %zu bunnies (commit %.1f ms, %.1f MB on the device), %d x %d primary rays, %.0f%% hit:\n",
                forest_count, built.build_ms, scene.stats().device_bytes / 1e6, size, size,
                100.0 * static_cast<double>(hit_count) / static_cast<double>(n));
    std::string embree_rate = "-", ratio = "-", agree = "-";
    std::vector<double> rtcl_times;
#ifdef RTCL_HAVE_EMBREE
    // The two interleaved, call by call (as the identity figures), so that
    // a change in the machine's load falls on both alike.
    embree_scene.place(placed);
    std::vector<double> ms;
    std::vector<rtcl::bench::InstanceHit> answers;
    for (int r = 0; r <= repeat; ++r) {
      const double rtcl_call = trace_rtcl();
      const double traced = embree_scene.trace(rays, &answers);
      if (r > 0) {
        rtcl_times.push_back(rtcl_call);
        ms.push_back(traced);
      }
    }
    const double rtcl_ms = median(rtcl_times);
    const double embree_ms = median(ms);
    std::size_t same = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const bool embree_hit = answers[i].prim >= 0;
      same += embree_hit == (hits[i].prim >= 0) &&
              (!embree_hit || (answers[i].instance == ids[i] && answers[i].prim == hits[i].prim));
    }
    embree_rate = fixed(mrays / embree_ms, 1);
    ratio = fixed(embree_ms / rtcl_ms, 2);
    agree = fixed(100.0 * static_cast<double>(same) / static_cast<double>(n), 2);
#else
    for (int r = 0; r <= repeat; ++r) {
      const double rtcl_call = trace_rtcl();
      if (r > 0) rtcl_times.push_back(rtcl_call);
    }
    const double rtcl_ms = median(rtcl_times);
#endif
    std::printf("| rtcl Mrays/s | Embree rtcIntersect1 Mrays/s | rtcl/Embree | same instance and triangle %% |\n|---|---|---|---|\n");
    std::printf("| %.1f | %s | %s | %s |\n", mrays / rtcl_ms, embree_rate.c_str(), ratio.c_str(), agree.c_str());
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "rtcl_instances_bench: error: %s\n", e.what());
  return 1;
}
