// Many rays through the host-array API in bounded memory
// (docs/benchmarks.md, "A billion rays"): the caller generates --rays rays
// batch by batch (--batch rays a batch, into one array it reuses) and traces
// each batch with Accel::trace on host arrays against a `bvh` of --scene:
//   - the first half of a batch: camera rays through jittered points of a
//     4096 x 4096 image of the scene's benchmark camera, in pixel order,
//     closest hit, Coherence::incoherent;
//   - the second half: diffuse rays from random points of random triangles
//     (either side), cosine-distributed about the normal, closest hit,
//     Coherence::scattered.
// Every ray is a function of its global index (a hash), so that any run
// traces the same rays. After each batch it reports the host's resident
// memory (VmRSS, /proc/self/status), the device buffers rtcl holds
// (Device::allocated_bytes), the trace rate of the batch (Mrays/s: its rays
// over the wall time of its two trace calls; generation not included) and
// the fraction of rays that hit, as a Markdown row on stdout and, with
// --json FILE, one JSON object a line.
//
// Exit status: 0; 1 on an error, a rate that is not finite and positive, or
// no hit in a batch; 3 when the last batch's resident memory or device
// bytes differ from the first batch's by more than --tolerance (a fraction;
// memory not flat); 77 with --missing-scene-skips when the scene file is
// absent (ctest's skip).
//
//   rtcl_billion_rays_bench [--rays 1e9] [--batch 16777216] [--scene bunny] [--scenes-dir DIR]
//                           [--accel bvh] [--tolerance 0.05] [--json FILE] [--missing-scene-skips]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include <glm/glm.hpp>

#include "bench/support/ray_sets.hpp"
#include "bench/support/scene_catalog.hpp"
#include "bench/support/scenes_dir.hpp"
#include "rtcl/rtcl.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "rtcl/scene/orthonormal_basis.hpp"
#include "rtcl/shared/render_layouts.h"  // rtcl_hash

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kImageSide = 4096;  // the camera rays' virtual image
constexpr float kInfinity = std::numeric_limits<float>::infinity();

struct Options {
  std::uint64_t rays = 1'000'000'000;
  std::uint64_t batch = std::uint64_t{1} << 24;
  std::string scene = "bunny", scenes_dir = rtcl::bench::scenes_dir(), accel = "bvh", json;
  double tolerance = 0.05;
  bool missing_scene_skips = false;
};

// A count given as an integer or in scientific notation (1e9).
std::uint64_t parse_count(const std::string& flag, const std::string& text) {
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !(value >= 1.0) || value > 1e15 || value != std::floor(value))
    throw rtcl::Error(flag + " '" + text + "': expected a whole number >= 1 (e.g. 1000000 or 1e9)");
  return static_cast<std::uint64_t>(value);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw rtcl::Error(arg + ": needs a value");
      return argv[++i];
    };
    if (arg == "--rays") o.rays = parse_count(arg, value());
    else if (arg == "--batch") o.batch = parse_count(arg, value());
    else if (arg == "--scene") o.scene = value();
    else if (arg == "--scenes-dir") o.scenes_dir = value();
    else if (arg == "--accel") o.accel = value();
    else if (arg == "--json") o.json = value();
    else if (arg == "--missing-scene-skips") o.missing_scene_skips = true;
    else if (arg == "--tolerance") {
      std::string text = value();
      std::size_t used = 0;
      try {
        o.tolerance = std::stod(text, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != text.size() || !(o.tolerance >= 0.0 && o.tolerance <= 1.0))
        throw rtcl::Error("--tolerance '" + text + "': expected a fraction in [0, 1]");
    } else
      throw rtcl::Error(arg + ": unknown option (--rays, --batch, --scene, --scenes-dir, --accel, --tolerance, "
                              "--json, --missing-scene-skips)");
  }
  if (o.batch < 2) throw rtcl::Error("--batch must be >= 2 (half camera, half diffuse rays)");
  o.batch = std::min(o.batch, o.rays);
  return o;
}

// A kB field of /proc/self/status (VmRSS, VmHWM) in bytes; 0 where absent.
std::size_t status_bytes(const std::string& field) {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind(field + ":", 0) == 0) return std::stoull(line.substr(field.size() + 1)) * 1024;
  return 0;
}

float unit_float(std::uint32_t bits) { return static_cast<float>(bits >> 8) * 0x1p-24f; }  // [0, 1)

// The k-th random number of global ray `ray`.
std::uint32_t ray_hash(std::uint64_t ray, std::uint32_t k) {
  return rtcl::rtcl_hash(static_cast<std::uint32_t>(ray) ^ rtcl::rtcl_hash(static_cast<std::uint32_t>(ray >> 32) * 4u + k));
}

class RayGenerator {
 public:
  RayGenerator(const rtcl::Geometry& geometry, const rtcl::bench::Camera& camera) : geometry_(geometry) {
    forward_ = glm::normalize(camera.target - camera.eye);
    right_ = glm::normalize(glm::cross(forward_, camera.up));
    up_ = glm::cross(right_, forward_);
    half_ = std::tan(0.5f * glm::radians(camera.fov_y_deg));
    eye_ = camera.eye;
    glm::vec3 extent = geometry.bounds().extent();
    extent_ = std::max({extent.x, extent.y, extent.z});
  }

  // Camera ray number `index` (pixel index % the image's pixel count,
  // jittered within the pixel).
  rtcl::Ray camera(std::uint64_t index, std::uint64_t global) const {
    const std::uint64_t pixel = index % (std::uint64_t{kImageSide} * kImageSide);
    const float x = static_cast<float>(pixel % kImageSide) + unit_float(ray_hash(global, 0));
    const float y = static_cast<float>(pixel / kImageSide) + unit_float(ray_hash(global, 1));
    const float sx = (2.0f * x / kImageSide - 1.0f) * half_, sy = (1.0f - 2.0f * y / kImageSide) * half_;
    glm::vec3 d = glm::normalize(forward_ + sx * right_ + sy * up_);
    return rtcl::Ray{eye_.x, eye_.y, eye_.z, d.x, d.y, d.z, 0.0f, kInfinity};
  }

  // A diffuse ray from a uniform point of a random triangle, off the side
  // a hash bit picks, cosine-distributed about that side's normal.
  rtcl::Ray diffuse(std::uint64_t global) const {
    const auto& triangles = geometry_.triangles;
    const glm::uvec3& tri = triangles[ray_hash(global, 2) % triangles.size()];
    const glm::vec3 v0 = geometry_.vertices[tri.x], v1 = geometry_.vertices[tri.y], v2 = geometry_.vertices[tri.z];
    const float s = std::sqrt(unit_float(ray_hash(global, 3))), r = unit_float(ray_hash(global, 4));
    const glm::vec3 p = (1.0f - s) * v0 + s * (1.0f - r) * v1 + s * r * v2;
    glm::vec3 n = glm::cross(v1 - v0, v2 - v0);
    const float length = glm::length(n);
    n = length > 0.0f ? n / length : glm::vec3(0.0f, 0.0f, 1.0f);
    if (ray_hash(global, 5) & 1u) n = -n;
    const glm::vec3 o = p + rtcl::bench::spawn_offset(p, extent_) * n;
    const float u1 = unit_float(ray_hash(global, 6)), phi = 6.28318530718f * unit_float(ray_hash(global, 7));
    glm::vec3 t1, t2;
    rtcl::orthonormal_basis(n, t1, t2);
    const float radius = std::sqrt(u1);
    glm::vec3 d = glm::normalize(radius * std::cos(phi) * t1 + radius * std::sin(phi) * t2 +
                                 std::sqrt(std::max(0.0f, 1.0f - u1)) * n);
    return rtcl::Ray{o.x, o.y, o.z, d.x, d.y, d.z, 0.0f, kInfinity};
  }

  // Rays [first, first + out.size()) of the run: camera rays in the first
  // half of out, diffuse rays in the second; on every hardware thread.
  void fill(std::uint64_t first, std::vector<rtcl::Ray>& out, std::size_t camera_count,
            std::uint64_t camera_first) const {
    const std::size_t threads = std::max(1u, std::thread::hardware_concurrency());
    const std::size_t n = out.size(), chunk = (n + threads - 1) / threads;
    std::vector<std::thread> workers;
    for (std::size_t t = 0; t < threads; ++t)
      workers.emplace_back([&, t] {
        for (std::size_t i = t * chunk; i < std::min(n, (t + 1) * chunk); ++i)
          out[i] = i < camera_count ? camera(camera_first + i, first + i) : diffuse(first + i);
      });
    for (std::thread& w : workers) w.join();
  }

 private:
  const rtcl::Geometry& geometry_;
  glm::vec3 eye_, forward_, right_, up_;
  float half_ = 1.0f, extent_ = 1.0f;
};

double mib(std::size_t bytes) { return static_cast<double>(bytes) / (1024.0 * 1024.0); }

// |last - first| / first (0 when both are 0).
double change(std::size_t first, std::size_t last) {
  if (first == 0) return last == 0 ? 0.0 : std::numeric_limits<double>::infinity();
  return std::abs(static_cast<double>(last) - static_cast<double>(first)) / static_cast<double>(first);
}

}  // namespace

int main(int argc, char** argv) try {
  const Options o = parse(argc, argv);
  const rtcl::bench::SceneSpec* spec = rtcl::bench::find_scene_spec(o.scene);
  if (!spec) throw rtcl::Error("--scene " + o.scene + ": unknown scene");
  const std::string path = o.scenes_dir + "/" + spec->file;
  if (!std::filesystem::exists(path)) {
    if (o.missing_scene_skips) {
      std::printf("skipped: --scene %s: no file %s (set RTCL_SCENES_DIR)\n", o.scene.c_str(), path.c_str());
      return 77;
    }
    throw rtcl::Error("--scene " + o.scene + ": no file " + path + " (set RTCL_SCENES_DIR or --scenes-dir)");
  }
  rtcl::Geometry geometry = rtcl::load_mesh(path).geometry;
  if (geometry.triangles.empty()) throw rtcl::Error("--scene " + o.scene + ": no triangles in " + path);
  const rtcl::bench::Camera camera = spec->fit ? rtcl::bench::fit_camera(geometry.bounds()) : spec->camera;
  rtcl::Device device = rtcl::Device::open();
  auto accel = rtcl::make_accel(device, o.accel, geometry);
  const RayGenerator generator(geometry, camera);

  std::FILE* json = nullptr;
  if (!o.json.empty() && !(json = std::fopen(o.json.c_str(), "w")))
    throw rtcl::Error("--json " + o.json + ": cannot be written");
  const std::uint64_t batches = (o.rays + o.batch - 1) / o.batch;
  std::printf("device: %s; %s over %s (%zu triangles); %llu rays in %llu batches of up to %llu "
              "(half camera rays, closest, incoherent; half diffuse rays, closest, scattered)\n\n",
              device.info().name.c_str(), o.accel.c_str(), o.scene.c_str(), geometry.triangles.size(),
              static_cast<unsigned long long>(o.rays), static_cast<unsigned long long>(batches),
              static_cast<unsigned long long>(o.batch));
  std::printf("| batch | rays | generate ms | trace ms | Mrays/s | hit fraction | host RSS MiB | device MiB |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  std::fflush(stdout);

  std::vector<rtcl::Ray> rays;
  std::vector<rtcl::Hit> hits;
  std::size_t rss_first = 0, rss_last = 0, device_first = 0, device_last = 0;
  double trace_ms_total = 0.0, mrays_min = std::numeric_limits<double>::infinity(), mrays_max = 0.0;
  bool valid = true;
  std::uint64_t camera_done = 0;
  const auto start = Clock::now();
  for (std::uint64_t b = 0; b < batches; ++b) {
    const std::uint64_t first = b * o.batch;
    const std::size_t n = static_cast<std::size_t>(std::min(o.batch, o.rays - first));
    const std::size_t camera_count = n / 2;
    rays.resize(n);
    hits.resize(n);
    auto t0 = Clock::now();
    generator.fill(first, rays, camera_count, camera_done);
    camera_done += camera_count;
    auto t1 = Clock::now();
    const std::span<const rtcl::Ray> all(rays);
    const std::span<rtcl::Hit> out(hits);
    accel->trace(rtcl::Query::closest, all.first(camera_count), out.first(camera_count),
                 rtcl::Coherence::incoherent);
    accel->trace(rtcl::Query::closest, all.subspan(camera_count), out.subspan(camera_count),
                 rtcl::Coherence::scattered);
    auto t2 = Clock::now();
    const double generate_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
    const double trace_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
    const double mrays = static_cast<double>(n) / (trace_ms * 1e3);
    std::size_t hit_count = 0;
    for (const rtcl::Hit& h : hits) hit_count += h.prim >= 0 ? 1 : 0;
    const double hit_fraction = static_cast<double>(hit_count) / static_cast<double>(n);
    const std::size_t rss = status_bytes("VmRSS"), on_device = device.allocated_bytes();
    if (b == 0) rss_first = rss, device_first = on_device;
    rss_last = rss, device_last = on_device;
    trace_ms_total += trace_ms;
    mrays_min = std::min(mrays_min, mrays);
    mrays_max = std::max(mrays_max, mrays);
    if (!std::isfinite(mrays) || !(mrays > 0.0) || hit_count == 0) valid = false;
    std::printf("| %llu | %zu | %.0f | %.0f | %.2f | %.3f | %.1f | %.2f |\n", static_cast<unsigned long long>(b), n,
                generate_ms, trace_ms, mrays, hit_fraction, mib(rss), mib(on_device));
    std::fflush(stdout);
    if (json) {
      std::fprintf(json,
                   "{\"batch\": %llu, \"rays\": %zu, \"generate_ms\": %.3f, \"trace_ms\": %.3f, \"mrays_per_s\": %.4f, "
                   "\"hit_fraction\": %.5f, \"host_rss_bytes\": %zu, \"device_bytes\": %zu}\n",
                   static_cast<unsigned long long>(b), n, generate_ms, trace_ms, mrays, hit_fraction, rss, on_device);
      std::fflush(json);
    }
  }
  const double wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  const double rss_change = change(rss_first, rss_last), device_change = change(device_first, device_last);
  const bool flat = rss_change <= o.tolerance && device_change <= o.tolerance;
  const double mean_mrays = static_cast<double>(o.rays) / (trace_ms_total * 1e3);
  std::printf("\nrays %llu in %.1f s (trace %.1f s): %.2f Mrays/s over all batches (batches %.2f .. %.2f); "
              "peak RSS %.1f MiB\n",
              static_cast<unsigned long long>(o.rays), wall_s, trace_ms_total * 1e-3, mean_mrays, mrays_min,
              mrays_max, mib(status_bytes("VmHWM")));
  std::printf("host RSS first/last batch %.1f / %.1f MiB (%+.2f%%); device %.2f / %.2f MiB (%+.2f%%): %s "
              "(tolerance %.1f%%)\n",
              mib(rss_first), mib(rss_last), 100.0 * (static_cast<double>(rss_last) / rss_first - 1.0),
              mib(device_first), mib(device_last),
              device_first ? 100.0 * (static_cast<double>(device_last) / device_first - 1.0) : 0.0,
              flat ? "flat" : "NOT FLAT", 100.0 * o.tolerance);
  if (json) {
    std::fprintf(json,
                 "{\"summary\": true, \"rays\": %llu, \"batches\": %llu, \"wall_s\": %.3f, \"mean_mrays_per_s\": %.4f, "
                 "\"host_rss_first_bytes\": %zu, \"host_rss_last_bytes\": %zu, \"device_first_bytes\": %zu, "
                 "\"device_last_bytes\": %zu, \"peak_rss_bytes\": %zu, \"tolerance\": %.4f, \"flat\": %s}\n",
                 static_cast<unsigned long long>(o.rays), static_cast<unsigned long long>(batches), wall_s,
                 mean_mrays, rss_first, rss_last, device_first, device_last, status_bytes("VmHWM"), o.tolerance,
                 flat ? "true" : "false");
    std::fclose(json);
  }
  if (!valid) {
    std::fprintf(stderr, "rtcl_billion_rays_bench: a batch had no hit or a rate that is not finite and positive\n");
    return 1;
  }
  return flat ? 0 : 3;
} catch (const std::exception& e) {
  std::fprintf(stderr, "rtcl_billion_rays_bench: error: %s\n", e.what());
  return 1;
}
