// Ray queries on host arrays against the same queries on device buffers and
// against Embree, same rays, same run (docs/benchmarks.md, "Host arrays"):
// for each scene, the primary rays of its benchmark camera (1024 x 1024 by
// default) through a `bvh`:
//   cl_mem     Accel::trace on buffers already on the device, until the
//              kernel ends (no upload, no read-back);
//   host       Accel::intersect's path on Ray records (Accel::trace with a
//              span): batches, upload, trace and read-back included;
//   host soa   the same from separate origin and direction arrays;
//   Embree     rtcIntersect1 on 2 threads over rays prepared outside the
//              timed region (bench/support/embree_baseline.hpp);
// then count and all_hits on host arrays beside closest hit. Each figure is
// the median of --repeat timed calls after one warm-up call; ratios are of
// medians measured in this run.
//
//   rtcl_query_bench [--scenes-dir DIR] [--scene bunny,dragon,sponza] [--size 1024] [--repeat 7]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "bench/support/ray_sets.hpp"
#include "bench/support/scene_catalog.hpp"
#include "bench/support/scenes_dir.hpp"
#include "rtcl/rtcl.hpp"
#include "rtcl/scene/mesh_io.hpp"
#ifdef RTCL_HAVE_EMBREE
#include "bench/support/embree_baseline.hpp"
#endif

namespace {

using Clock = std::chrono::steady_clock;

double median_ms(int repeat, const std::function<void()>& call) {
  call();  // warm-up: kernel builds, first touch of the buffers
  std::vector<double> ms;
  for (int i = 0; i < repeat; ++i) {
    auto start = Clock::now();
    call();
    ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) out.push_back(item);
  return out;
}

}  // namespace

int main(int argc, char** argv) try {
  std::string scenes_dir = rtcl::bench::scenes_dir(), scenes = "bunny,dragon,sponza";
  int size = 1024, repeat = 7;
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw rtcl::Error(arg + ": needs a value");
      return argv[++i];
    };
    if (arg == "--scenes-dir") scenes_dir = value();
    else if (arg == "--scene") scenes = value();
    else if (arg == "--size") size = std::stoi(value());
    else if (arg == "--repeat") repeat = std::stoi(value());
    else throw rtcl::Error(arg + ": unknown option (--scenes-dir, --scene, --size, --repeat)");
  }
  if (size < 8 || repeat < 1) throw rtcl::Error("--size must be >= 8 and --repeat >= 1");
  rtcl::Device device = rtcl::Device::open();
  std::printf("device: %s; %d x %d primary rays per scene; medians of %d calls\n\n", device.info().name.c_str(), size,
              size, repeat);
  std::printf("| scene | cl_mem Mrays/s | host | host/cl_mem | host soa | Embree rtcIntersect1 | host/Embree | count | all_hits |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& name : split(scenes)) {
    const rtcl::bench::SceneSpec* spec = rtcl::bench::find_scene_spec(name);
    if (!spec) throw rtcl::Error("--scene " + name + ": unknown scene");
    rtcl::Geometry geometry = rtcl::load_mesh(scenes_dir + "/" + spec->file).geometry;
    rtcl::bench::Camera camera = spec->fit ? rtcl::bench::fit_camera(geometry.bounds()) : spec->camera;
    std::vector<rtcl::Ray> rays = rtcl::bench::primary_rays(camera, size, size);
    const std::size_t n = rays.size();
    auto bvh = rtcl::make_accel(device, "bvh", geometry);
    const double mrays = static_cast<double>(n) * 1e-3;  // rays per ms -> Mrays/s

    cl::Buffer ray_buffer = device.upload(rays.data(), n * sizeof(rtcl::Ray), "bench rays");
    cl::Buffer hit_buffer = device.allocate(n * sizeof(rtcl::Hit), "bench hits");
    const double cl_ms = median_ms(repeat, [&] {
      bvh->trace(rtcl::Query::closest, ray_buffer, hit_buffer, n).wait();
    });
    std::vector<rtcl::Hit> hits(n);
    const double host_ms = median_ms(repeat, [&] { bvh->trace(rtcl::Query::closest, rays, hits); });
    std::vector<float> origins, directions;
    for (const rtcl::Ray& r : rays) {
      origins.insert(origins.end(), {r.ox, r.oy, r.oz});
      directions.insert(directions.end(), {r.dx, r.dy, r.dz});
    }
    const double soa_ms =
        median_ms(repeat, [&] { bvh->trace(rtcl::Query::closest, rtcl::Rays(origins, directions), hits); });
    std::vector<std::uint32_t> counts(n);
    const double count_ms = median_ms(repeat, [&] { bvh->count(rays, counts); });
    const double all_ms = median_ms(repeat, [&] { rtcl::AllHits all = bvh->all_hits(rays); });
    std::string embree = "-", versus = "-";
#ifdef RTCL_HAVE_EMBREE
    rtcl::bench::EmbreeScene scene(geometry, rtcl::bench::EmbreeQuality::standard, 2);
    // Only rtcIntersect1's loop is timed, as Embree frames it; the rays are
    // converted before each timed call.
    std::vector<double> ms;
    for (int i = 0; i <= repeat; ++i) {
      scene.prepare(rtcl::Query::closest, rays.data(), n);
      auto start = Clock::now();
      scene.trace_prepared(2);
      if (i > 0) ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    }
    std::sort(ms.begin(), ms.end());
    const double embree_ms = ms[ms.size() / 2];
    char text[64];
    std::snprintf(text, sizeof text, "%.1f", mrays / embree_ms);
    embree = text;
    std::snprintf(text, sizeof text, "%.2f", embree_ms / host_ms);
    versus = text;
#endif
    std::printf("| %s | %.1f | %.1f | %.2f | %.1f | %s | %s | %.1f | %.1f |\n", name.c_str(), mrays / cl_ms,
                mrays / host_ms, cl_ms / host_ms, mrays / soa_ms, embree.c_str(), versus.c_str(), mrays / count_ms,
                mrays / all_ms);
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "rtcl_query_bench: error: %s\n", e.what());
  return 1;
}
