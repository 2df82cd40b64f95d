// Refit against a full rebuild and against Embree's refit, same vertices,
// same run (docs/api.md, "Refit"): for each scene (bunny, dragon and a
// 1M-triangle random soup by default) moved by a smooth deformation (a sine
// field, 2% of the scene's size, 1.5 periods across it):
//   rebuild      make_accel("bvh") over the moved vertices: build, flatten
//                and upload (what a refit replaces);
//   refit        Accel::refit to the moved vertices (checks, upload of the
//                vertices and indices, the device update, the cost's
//                read-back), alternating between two deformations so that
//                every call moves the vertices;
//   Embree build rtcCommitScene of a new scene of the moved mesh at
//                RTC_BUILD_QUALITY_MEDIUM (Embree's default binned SAH);
//   Embree refit rtcUpdateGeometryBuffer + rtcCommitGeometry +
//                rtcCommitScene of a RTC_SCENE_FLAG_DYNAMIC scene at
//                RTC_BUILD_QUALITY_LOW whose mesh has
//                RTC_BUILD_QUALITY_REFIT (Embree 3 honours the geometry's
//                quality only in its two-level LOW mode); the vertices are
//                written into Embree's buffer outside the timed region.
//                That Embree really refits is checked in the same run: its
//                first commit (a build) against the later ones, and a
//                second scene whose mesh has RTC_BUILD_QUALITY_MEDIUM in
//                the same LOW mode (a rebuild of the mesh at every commit);
//                the "Embree refits" column says yes when its refit commit
//                takes under half of both (a rebuild would take as long).
// The two refits are timed in one or both of two ways (--timing):
//   interleaved  each of rtcl's refits right before one of Embree's, so
//                that both see the same moments of a shared machine;
//                --gap MS sleeps before each call (untimed): the threads of
//                either library spin for a while after their work (Embree's
//                TBB workers, rtcl's host pool), and without a gap they
//                may take cores from the other's next call (with one, each
//                call may wake its threads from sleep instead);
//   blocks       all of rtcl's refits, then all of Embree's (each with its
//                caches to itself, as an application refitting one mesh
//                per frame has them).
// Then the trace speed after 10 refits of a growing deformation (the sine's
// amplitude 1% .. 10% of the size) against a fresh build over the same
// vertices: primary rays of a camera fitted to the moved scene and their
// diffuse bounces, Accel::trace on device buffers. Each figure is the
// median of --repeat calls after one warm-up call; Embree runs on 2
// threads (--threads).
//
//   rtcl_refit_bench [--scenes-dir DIR] [--scene bunny,dragon,soup] [--soup 1000000] [--size 512]
//                    [--repeat 7] [--threads 2] [--timing interleaved,blocks] [--gap 0]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <memory>
#include <utility>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench/support/ray_sets.hpp"
#include "bench/support/scene_catalog.hpp"
#include "bench/support/scenes_dir.hpp"
#include "bench/support/timing.hpp"
#include "rtcl/rtcl.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "rtcl/scene/procedural.hpp"
#ifdef RTCL_HAVE_EMBREE
#include <embree3/rtcore.h>
#endif

namespace {

using rtcl::bench::Clock;
using rtcl::bench::median;
using rtcl::bench::ms_since;

// Median of `repeat` timed calls after one warm-up; call(k) gets the call's
// index (0 = the warm-up).
double median_ms(int repeat, const std::function<void(int)>& call) {
  call(0);
  std::vector<double> ms;
  for (int k = 1; k <= repeat; ++k) {
    const auto start = Clock::now();
    call(k);
    ms.push_back(ms_since(start));
  }
  return median(ms);
}

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) out.push_back(item);
  return out;
}

// Every vertex moved by a smooth field: `amplitude` times the box's largest
// side, `waves` periods across the box.
std::vector<glm::vec3> sine_deformed(const std::vector<glm::vec3>& vertices, const rtcl::Aabb& box, float amplitude,
                                     float waves) {
  const glm::vec3 e = box.extent();
  const float size = std::max({e.x, e.y, e.z});
  const float k = 2.0f * 3.14159265f * waves / size;
  std::vector<glm::vec3> out(vertices.size());
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const glm::vec3 p = vertices[i] - box.lower;
    out[i] = vertices[i] +
             amplitude * size * glm::vec3(std::sin(k * p.y), std::sin(k * p.z + 1.0f), std::sin(k * p.x + 2.0f));
  }
  return out;
}

#ifdef RTCL_HAVE_EMBREE
// One Embree scene of one triangle mesh, vertices in Embree's own buffer.
class EmbreeMesh {
 public:
  EmbreeMesh(RTCDevice device, const rtcl::Geometry& g, RTCSceneFlags flags, RTCBuildQuality scene_quality,
             RTCBuildQuality mesh_quality)
      : vertex_count_(g.vertices.size()) {
    scene_ = rtcNewScene(device);
    rtcSetSceneFlags(scene_, flags);
    rtcSetSceneBuildQuality(scene_, scene_quality);
    mesh_ = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(mesh_, mesh_quality);
    vertices_ = static_cast<float*>(rtcSetNewGeometryBuffer(mesh_, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                            3 * sizeof(float), vertex_count_));
    auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(mesh_, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(unsigned), g.triangles.size()));
    std::memcpy(indices, g.triangles.data(), g.triangles.size() * 3 * sizeof(unsigned));
    set_vertices(g.vertices);
    rtcCommitGeometry(mesh_);
    rtcAttachGeometry(scene_, mesh_);
    check(device);
  }
  ~EmbreeMesh() {
    rtcReleaseGeometry(mesh_);
    rtcReleaseScene(scene_);
  }
  EmbreeMesh(const EmbreeMesh&) = delete;
  EmbreeMesh& operator=(const EmbreeMesh&) = delete;

  void set_vertices(const std::vector<glm::vec3>& v) { std::memcpy(vertices_, v.data(), vertex_count_ * 12); }
  // What an application does after moving the vertices (the first call builds).
  void commit() {
    rtcUpdateGeometryBuffer(mesh_, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcCommitGeometry(mesh_);
    rtcCommitScene(scene_);
  }
  // The closest hit's primitive of each ray (-1: miss), on this thread.
  std::vector<int> closest(const std::vector<rtcl::Ray>& rays) const {
    std::vector<int> prims(rays.size());
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      RTCRayHit rh{};
      const rtcl::Ray& r = rays[i];
      rh.ray = {r.ox, r.oy, r.oz, r.tmin, r.dx, r.dy, r.dz, 0.0f, r.tmax, 0xffffffffu, 0, 0};
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(scene_, &context, &rh);
      prims[i] = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? -1 : static_cast<int>(rh.hit.primID);
    }
    return prims;
  }
  static void check(RTCDevice device) {
    if (RTCError error = rtcGetDeviceError(device); error != RTC_ERROR_NONE)
      throw rtcl::Error("Embree error " + std::to_string(error));
  }

 private:
  std::size_t vertex_count_;
  RTCScene scene_ = nullptr;
  RTCGeometry mesh_ = nullptr;
  float* vertices_ = nullptr;
};
#endif

// Trace time (ms, median) of closest-hit queries on device buffers.
double trace_ms(const rtcl::Device& device, const rtcl::Accel& accel, const std::vector<rtcl::Ray>& rays, int repeat,
                rtcl::Coherence coherence) {
  cl::Buffer ray_buffer = device.upload(rays.data(), rays.size() * sizeof(rtcl::Ray), "bench rays");
  cl::Buffer hit_buffer = device.allocate(rays.size() * sizeof(rtcl::Hit), "bench hits");
  return median_ms(repeat, [&](int) {
    accel.trace(rtcl::Query::closest, ray_buffer, hit_buffer, rays.size(), {}, coherence).wait();
  });
}

}  // namespace

int main(int argc, char** argv) try {
  std::string scenes_dir = rtcl::bench::scenes_dir(), scenes = "bunny,dragon,soup", timing = "interleaved,blocks";
  std::size_t soup = 1000000;
  int size = 512, repeat = 7, threads = 2;
  double gap_ms = 0.0;
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw rtcl::Error(arg + ": needs a value");
      return argv[++i];
    };
    // A numeric value: the whole text a number, else an error naming the flag.
    auto number = [&]() -> double {
      const std::string text = value();
      std::size_t used = 0;
      double x = 0.0;
      try {
        x = std::stod(text, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || used != text.size()) throw rtcl::Error(arg + " " + text + ": not a number");
      return x;
    };
    if (arg == "--scenes-dir") scenes_dir = value();
    else if (arg == "--scene") scenes = value();
    else if (arg == "--soup") soup = static_cast<std::size_t>(std::max(0.0, number()));
    else if (arg == "--size") size = static_cast<int>(std::clamp(number(), -1.0, 1e6));
    else if (arg == "--repeat") repeat = static_cast<int>(std::clamp(number(), -1.0, 1e6));
    else if (arg == "--threads") threads = static_cast<int>(std::clamp(number(), -1.0, 1e4));
    else if (arg == "--timing") timing = value();
    else if (arg == "--gap") gap_ms = number();
    else throw rtcl::Error(arg + ": unknown option (--scenes-dir, --scene, --soup, --size, --repeat, --threads, --timing, --gap)");
  }
  if (size < 8 || repeat < 1 || threads < 1 || soup < 1) throw rtcl::Error("--size >= 8, --repeat, --threads, --soup >= 1");
  if (!(gap_ms >= 0.0 && gap_ms <= 1000.0)) throw rtcl::Error("--gap: milliseconds in [0, 1000]");
  const auto gap = std::chrono::duration<double, std::milli>(gap_ms);
  const std::vector<std::string> timings = split(timing);
  if (timings.empty()) throw rtcl::Error("--timing: empty (interleaved, blocks or both)");
  for (const std::string& t : timings)
    if (t != "interleaved" && t != "blocks") throw rtcl::Error("--timing " + t + ": unknown (interleaved, blocks)");
  rtcl::Device device = rtcl::Device::open();
#ifdef RTCL_HAVE_EMBREE
  const std::string config = "threads=" + std::to_string(threads);
  RTCDevice embree = rtcNewDevice(config.c_str());
  if (!embree) throw rtcl::Error("Embree: rtcNewDevice failed");
#endif
  std::printf("device: %s; medians of %d calls; Embree on %d threads\n\n", device.info().name.c_str(), repeat, threads);

  struct Scene {
    std::string name;
    rtcl::Geometry geometry;
    rtcl::Aabb box;
  };
  std::vector<Scene> loaded;
  for (const std::string& name : split(scenes)) {
    rtcl::Geometry g;
    if (name == "soup") {
      g = rtcl::random_triangle_soup(soup, 1);
    } else {
      const rtcl::bench::SceneSpec* spec = rtcl::bench::find_scene_spec(name);
      if (!spec) throw rtcl::Error("--scene " + name + ": unknown scene (a catalogue scene or soup)");
      g = rtcl::load_mesh(scenes_dir + "/" + spec->file).geometry;
    }
    rtcl::validate(g);
    const rtcl::Aabb box = g.bounds();
    loaded.push_back({name, std::move(g), box});
  }

  std::printf("## Refit after a smooth deformation\n\n");
  std::printf("| scene | triangles | rebuild ms | Embree build ms | cost ratio | timing | refit ms | refit/rebuild | "
              "Embree refit ms | refit/Embree refit | Embree first commit ms | Embree LOW+MEDIUM commit ms | "
              "Embree refits | Embree agrees |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Scene& s : loaded) {
    const rtcl::Geometry& g = s.geometry;
    rtcl::Geometry moved[2] = {g, g};
    moved[0].vertices = sine_deformed(g.vertices, s.box, 0.02f, 1.5f);
    moved[1].vertices = sine_deformed(g.vertices, s.box, -0.02f, 1.5f);
    const double rebuild_ms = median_ms(repeat, [&](int) { auto fresh = rtcl::make_accel(device, "bvh", moved[0]); });
    auto accel = rtcl::make_accel(device, "bvh", g);
    double cost_ratio = 0.0;
    const auto refit = [&](int k) {
      cost_ratio = accel->refit(moved[k % 2], {.max_cost_ratio = INFINITY}).cost_ratio();
    };
    // Per way of timing (interleaved, blocks): rtcl's refit ms and Embree's
    // (-1: no Embree).
    std::vector<std::pair<double, double>> timed(timings.size(), {0.0, -1.0});
    std::string embree_build = "-", first = "-", medium = "-", refits = "-", agrees = "-";
#ifndef RTCL_HAVE_EMBREE
    for (std::size_t w = 0; w < timings.size(); ++w) timed[w].first = median_ms(repeat, refit);
#else
    char text[96];
    // The commit alone: the scene's setup (buffer copies) is not Embree's build.
    std::vector<double> builds;
    for (int k = 0; k <= repeat; ++k) {
      EmbreeMesh scene(embree, moved[0], RTC_SCENE_FLAG_NONE, RTC_BUILD_QUALITY_MEDIUM, RTC_BUILD_QUALITY_MEDIUM);
      const auto start = Clock::now();
      scene.commit();
      if (k > 0) builds.push_back(ms_since(start));
    }
    const double embree_build_ms = median(builds);
    // A dynamic LOW-quality scene of the mesh at `mesh_quality`: its first
    // commit (a build) into *first_ms, the median of the later ones (each
    // after moving the vertices) returned. `between(k)`, when given, runs
    // before each commit (outside its time).
    const auto timed_commits = [&](RTCBuildQuality mesh_quality, double* first_ms,
                                   const std::function<void(int)>& between) {
      auto scene = std::make_unique<EmbreeMesh>(embree, g, RTC_SCENE_FLAG_DYNAMIC, RTC_BUILD_QUALITY_LOW, mesh_quality);
      const auto start = Clock::now();
      scene->commit();
      *first_ms = ms_since(start);
      std::vector<double> ms;
      for (int k = 0; k <= repeat; ++k) {
        if (between) between(k);
        scene->set_vertices(moved[k % 2].vertices);
        const auto at = Clock::now();
        scene->commit();
        if (k > 0) ms.push_back(ms_since(at));
      }
      EmbreeMesh::check(embree);
      return std::pair(median(ms), std::move(scene));
    };
    double first_ms = 0.0, medium_first_ms = 0.0;
    std::unique_ptr<EmbreeMesh> refitted;
    for (std::size_t w = 0; w < timings.size(); ++w) {
      double block_first_ms = 0.0;
      if (timings[w] == "interleaved") {
        std::vector<double> refit_runs;
        auto [embree_ms, scene] = timed_commits(RTC_BUILD_QUALITY_REFIT, &block_first_ms, [&](int k) {
          std::this_thread::sleep_for(gap);
          const auto start = Clock::now();
          refit(k);
          if (k > 0) refit_runs.push_back(ms_since(start));
          std::this_thread::sleep_for(gap);
        });
        timed[w] = {median(refit_runs), embree_ms};
        refitted = std::move(scene);
      } else {
        const double ours = median_ms(repeat, refit);
        auto [embree_ms, scene] = timed_commits(RTC_BUILD_QUALITY_REFIT, &block_first_ms, {});
        timed[w] = {ours, embree_ms};
        refitted = std::move(scene);
      }
      if (w == 0) first_ms = block_first_ms;
    }
    const double medium_ms = timed_commits(RTC_BUILD_QUALITY_MEDIUM, &medium_first_ms, {}).first;
    // Embree refits when its refit commits take under half of a build (its
    // first commit) and of a rebuild of the mesh (a MEDIUM-quality mesh in
    // the same LOW-quality dynamic scene): a rebuild would take as long.
    double slowest = 0.0;
    for (const auto& [ours, theirs] : timed) slowest = std::max(slowest, theirs);
    const double share = slowest / std::min(first_ms, medium_ms);
    std::snprintf(text, sizeof text, "%s (%.2fx a rebuild)", share < 0.5 ? "yes" : "NO", share);
    refits = text;
    // Embree's refitted scene answers for the last vertices it was given
    // (moved[repeat % 2]) as our refitted structure does for its last ones.
    accel->refit(moved[repeat % 2]);
    const rtcl::bench::Camera camera = rtcl::bench::fit_camera(moved[repeat % 2].bounds());
    const std::vector<rtcl::Ray> rays = rtcl::bench::primary_rays(camera, 128, 128);
    const std::vector<rtcl::Hit> ours = accel->intersect(rays);
    const std::vector<int> theirs = refitted->closest(rays);
    std::size_t same = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) same += ours[i].prim == theirs[i];
    std::snprintf(text, sizeof text, "%.2f", embree_build_ms);
    embree_build = text;
    std::snprintf(text, sizeof text, "%.2f", first_ms);
    first = text;
    std::snprintf(text, sizeof text, "%.2f", medium_ms);
    medium = text;
    std::snprintf(text, sizeof text, "%.2f%%", 100.0 * static_cast<double>(same) / static_cast<double>(rays.size()));
    agrees = text;
#endif
    for (std::size_t w = 0; w < timings.size(); ++w) {
      const auto [refit_ms, embree_refit_ms] = timed[w];
      char theirs[32] = "-", versus[32] = "-";
      if (embree_refit_ms >= 0.0) {
        std::snprintf(theirs, sizeof theirs, "%.2f", embree_refit_ms);
        std::snprintf(versus, sizeof versus, "%.2f", refit_ms / embree_refit_ms);
      }
      std::printf("| %s | %zu | %.2f | %s | %.3f | %s | %.2f | %.3f | %s | %s | %s | %s | %s | %s |\n", s.name.c_str(),
                  g.triangles.size(), rebuild_ms, embree_build.c_str(), cost_ratio, timings[w].c_str(), refit_ms,
                  refit_ms / rebuild_ms, theirs, versus, first.c_str(), medium.c_str(), refits.c_str(),
                  agrees.c_str());
    }
    std::fflush(stdout);
  }

  std::printf("\n## Trace after 10 refits of a growing deformation (amplitude 1%% .. 10%% of the size)\n\n");
  std::printf("| scene | cost ratio | primary ms refitted | primary ms fresh | refitted/fresh | diffuse ms refitted | "
              "diffuse ms fresh | refitted/fresh |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (const Scene& s : loaded) {
    const rtcl::Geometry& g = s.geometry;
    auto accel = rtcl::make_accel(device, "bvh", g);
    rtcl::Geometry moved = g;
    rtcl::RefitStats stats;
    for (int step = 1; step <= 10; ++step) {
      moved.vertices = sine_deformed(g.vertices, s.box, 0.01f * static_cast<float>(step), 1.5f);
      stats = accel->refit(moved, {.max_cost_ratio = INFINITY});
    }
    auto fresh = rtcl::make_accel(device, "bvh", moved);
    const rtcl::bench::Camera camera = rtcl::bench::fit_camera(moved.bounds());
    const std::vector<rtcl::Ray> primary = rtcl::bench::primary_rays(camera, size, size);
    const std::vector<rtcl::Hit> hits = fresh->intersect(primary);
    const rtcl::bench::SecondaryRays secondary =
        rtcl::bench::secondary_rays(moved, primary, hits, rtcl::bench::fit_light(moved.bounds()));
    const double primary_refit = trace_ms(device, *accel, primary, repeat, rtcl::Coherence::incoherent);
    const double primary_fresh = trace_ms(device, *fresh, primary, repeat, rtcl::Coherence::incoherent);
    double diffuse_refit = 0.0, diffuse_fresh = 0.0;
    if (!secondary.diffuse.empty()) {
      diffuse_refit = trace_ms(device, *accel, secondary.diffuse, repeat, rtcl::Coherence::incoherent);
      diffuse_fresh = trace_ms(device, *fresh, secondary.diffuse, repeat, rtcl::Coherence::incoherent);
    }
    std::printf("| %s | %.3f | %.2f | %.2f | %.3f | %.2f | %.2f | %.3f |\n", s.name.c_str(), stats.cost_ratio(),
                primary_refit, primary_fresh, primary_refit / primary_fresh, diffuse_refit, diffuse_fresh,
                diffuse_fresh > 0.0 ? diffuse_refit / diffuse_fresh : 0.0);
    std::fflush(stdout);
  }
#ifdef RTCL_HAVE_EMBREE
  rtcReleaseDevice(embree);
#endif
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "rtcl_refit_bench: error: %s\n", e.what());
  return 1;
}
