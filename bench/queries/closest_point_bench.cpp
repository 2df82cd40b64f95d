// Closest-point queries: rtcl's Accel::closest_points on host arrays against
// Embree 3's rtcPointQuery, framed as Embree's closest_point tutorial (a
// point-query callback computing the point-triangle closest point, Ericson
// 5.1.5, and shrinking the query radius; RTCPointQueryContext), run by 2
// host threads each taking a contiguous share of the points. Same points
// (1M uniform over the mesh's box grown by 10% per side), same run; prints
// both rates (Mpoints/s, median of the timed runs after a warm-up), their
// ratio, and how well the two agree on the distances of a sample.
//
//   rtcl_closest_point_bench [points=1000000] [runs=5] [threads=2]
//
// A plain program (not part of rtcl_bench): Embree 3 is required.
#include <embree3/rtcore.h>
#include <stdlib.h>
#include <xmmintrin.h>
#include <pmmintrin.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "bench/support/scenes_dir.hpp"
#include "bench/support/timing.hpp"
#include "rtcl/accel.hpp"
#include "rtcl/device.hpp"
#include "rtcl/scene/mesh_io.hpp"

namespace {

using rtcl::bench::Clock;
using rtcl::bench::median;
using rtcl::bench::ms_since;

struct V3 {
  float x, y, z;
};
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator*(V3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
inline float dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// Ericson 5.1.5 (the tutorial's closestPointTriangle).
V3 closest_point_triangle(V3 p, V3 a, V3 b, V3 c) {
  const V3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.f && d2 <= 0.f) return a;
  const V3 bp = p - b;
  const float d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.f && d4 <= d3) return b;
  const V3 cp = p - c;
  const float d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.f && d5 <= d6) return c;
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.f && d1 >= 0.f && d3 <= 0.f) return a + ab * (d1 / (d1 - d3));
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.f && d2 >= 0.f && d6 <= 0.f) return a + ac * (d2 / (d2 - d6));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.f && (d4 - d3) >= 0.f && (d5 - d6) >= 0.f) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const float denom = 1.f / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

struct Mesh {
  const float* vertices;  // 3 per vertex
  const std::uint32_t* indices;
};

struct Result {
  float distance;
  unsigned prim;
};

struct QueryUser {
  const Mesh* mesh;
  Result* result;
};

bool closest_point_func(RTCPointQueryFunctionArguments* args) {
  const QueryUser* user = static_cast<const QueryUser*>(args->userPtr);
  const Mesh& m = *user->mesh;
  const std::uint32_t* t = m.indices + 3 * std::size_t{args->primID};
  auto vertex = [&](std::uint32_t i) { return V3{m.vertices[3 * i], m.vertices[3 * i + 1], m.vertices[3 * i + 2]}; };
  const V3 p{args->query->x, args->query->y, args->query->z};
  const V3 q = closest_point_triangle(p, vertex(t[0]), vertex(t[1]), vertex(t[2]));
  const V3 d = p - q;
  const float dist = std::sqrt(dot(d, d));
  if (dist < args->query->radius) {
    args->query->radius = dist;
    user->result->distance = dist;
    user->result->prim = args->primID;
    return true;  // the radius shrank
  }
  return false;
}

struct SceneRates {
  double rtcl_mps = 0.0, embree_mps = 0.0;
};

SceneRates run_scene(const rtcl::Device& device, RTCDevice embree, const std::string& path, std::size_t n,
                     int runs, unsigned threads) {
  rtcl::Geometry g = rtcl::load_mesh(path).geometry;
  rtcl::Aabb box = g.bounds();
  glm::vec3 lo = box.lower - 0.1f * box.extent(), hi = box.upper + 0.1f * box.extent();
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<glm::vec3> points(n);
  for (glm::vec3& p : points) p = lo + glm::vec3(unit(rng), unit(rng), unit(rng)) * (hi - lo);

  // rtcl
  auto accel = rtcl::make_accel(device, "bvh", g);
  std::vector<rtcl::PointHit> hits(n);
  accel->closest_points(points, hits);  // warm-up: kernel build, first launch
  std::vector<double> rtcl_s;
  for (int r = 0; r < runs; ++r) {
    auto t0 = Clock::now();
    accel->closest_points(points, hits);
    rtcl_s.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
  }

  // Embree
  std::vector<float> vertices;
  vertices.reserve(3 * g.vertices.size() + 1);
  for (const glm::vec3& v : g.vertices) vertices.insert(vertices.end(), {v.x, v.y, v.z});
  vertices.push_back(0.0f);
  std::vector<std::uint32_t> indices;
  for (const glm::uvec3& t : g.triangles) indices.insert(indices.end(), {t.x, t.y, t.z});
  Mesh mesh{vertices.data(), indices.data()};
  RTCScene scene = rtcNewScene(embree);
  RTCGeometry geom = rtcNewGeometry(embree, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, vertices.data(), 0, 12,
                             g.vertices.size());
  rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, indices.data(), 0, 12,
                             g.triangles.size());
  rtcSetGeometryPointQueryFunction(geom, closest_point_func);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(scene);
  std::vector<Result> results(n);
  auto embree_pass = [&] {
    auto share = [&](std::size_t begin, std::size_t end) {
      _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
      _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
      for (std::size_t i = begin; i < end; ++i) {
        RTCPointQuery query;
        query.x = points[i].x;
        query.y = points[i].y;
        query.z = points[i].z;
        query.time = 0.0f;
        query.radius = std::numeric_limits<float>::infinity();
        RTCPointQueryContext context;
        rtcInitPointQueryContext(&context);
        results[i] = {std::numeric_limits<float>::infinity(), RTC_INVALID_GEOMETRY_ID};
        QueryUser user{&mesh, &results[i]};
        rtcPointQuery(scene, &query, &context, nullptr, &user);
      }
    };
    std::vector<std::thread> helpers;
    for (unsigned t = 1; t < threads; ++t) helpers.emplace_back(share, n * t / threads, n * (t + 1) / threads);
    share(0, n / threads);
    for (auto& h : helpers) h.join();
  };
  embree_pass();  // warm-up
  std::vector<double> embree_s;
  for (int r = 0; r < runs; ++r) {
    auto t0 = Clock::now();
    embree_pass();
    embree_s.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
  }
  rtcReleaseScene(scene);

  // Agreement on a sample of 10000 points (every (n / 10000)-th).
  const double scale = std::max({double(glm::length(box.extent())), double(std::abs(box.lower.x)),
                                 double(std::abs(box.lower.y)), double(std::abs(box.lower.z)),
                                 double(std::abs(box.upper.x)), double(std::abs(box.upper.y)),
                                 double(std::abs(box.upper.z))});
  const double tol = 64.0 * std::ldexp(1.0, -24) * scale * 1.2;
  std::size_t step = std::max<std::size_t>(1, n / 10000), sampled = 0, disagree = 0, same_prim = 0;
  double worst = 0.0;
  for (std::size_t i = 0; i < n; i += step) {
    ++sampled;
    double diff = std::abs(double(hits[i].distance) - double(results[i].distance));
    worst = std::max(worst, diff);
    if (!(diff <= tol)) ++disagree;
    if (hits[i].prim == static_cast<std::int32_t>(results[i].prim)) ++same_prim;
  }

  SceneRates rates;
  rates.rtcl_mps = double(n) / median(rtcl_s) * 1e-6;
  rates.embree_mps = double(n) / median(embree_s) * 1e-6;
  std::printf("%-10s %8zu tris  rtcl bvh %7.3f Mpoints/s  Embree rtcPointQuery (%u threads) %7.3f Mpoints/s  "
              "ratio %.2fx\n",
              path.substr(path.rfind('/') + 1).c_str(), g.triangles.size(), rates.rtcl_mps, threads, rates.embree_mps,
              rates.rtcl_mps / rates.embree_mps);
  std::printf("           agreement on %zu sampled points: %zu beyond %.3g (64 float ulps of the scene), "
              "largest difference %.3g; same triangle %.2f%%\n",
              sampled, disagree, tol, worst, 100.0 * double(same_prim) / double(sampled));
  return rates;
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t n = argc > 1 ? std::stoul(argv[1]) : 1000000;
  int runs = argc > 2 ? std::stoi(argv[2]) : 5;
  unsigned threads = argc > 3 ? static_cast<unsigned>(std::stoul(argv[3])) : 2;
  if (!std::getenv("POCL_CACHE_DIR")) ::setenv("POCL_CACHE_DIR", RTCL_CLOSEST_BENCH_POCL_CACHE, 1);
  try {
    rtcl::Device device = rtcl::Device::open();
    std::string config = "threads=" + std::to_string(threads);
    RTCDevice embree = rtcNewDevice(config.c_str());
    if (!embree) throw rtcl::Error("Embree: rtcNewDevice failed");
    std::printf("device: %s; %zu points, median of %d runs after a warm-up\n", device.info().name.c_str(), n, runs);
    const std::string dir = rtcl::bench::scenes_dir();
    for (const char* scene : {"stanford_bunny/bunny.obj", "stanford_dragon_100k/dragon.obj"})
      run_scene(device, embree, dir + "/" + scene, n, runs, threads);
    rtcReleaseDevice(embree);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rtcl_closest_point_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
