// rtcl_ray_sort_ab: secondary rays sorted on the device before tracing,
// against the same rays traced as they come, in one process, launch by
// launch, on the bench/ scenes' shadow and diffuse rays (single-ray "bvh").
//
//   rtcl_ray_sort_ab SCENES ROUNDS KEY...
//   e.g. rtcl_ray_sort_ab bunny,sponza 7 o3d1 o4d0 d1o3
//
// A KEY names the sort key of kernels/bench/ray_sort.cl: "oNdM" = N origin
// bits and M direction bits per axis (2^(3(N+M)) buckets), direction bits
// low; "dMoN" = direction bits high. Per ray set: the unsorted trace; the
// trace of the rays in the host's 60-bit Morton order
// (render/ray_order.hpp: the trace alone, the host sort untimed); and per
// KEY the device pipeline count (key and histogram per chunk) -> offsets ->
// scatter (the rays into sorted order) -> trace -> unsort (the hits back
// into the caller's order), each stage's kernel time from OpenCL events.
// Every pipeline's hits are compared with the unsorted trace's bit for bit
// ("DIFFERS" when not). Rounds alternate the variants, the order rotated
// each round. Prints the medians of the stages, the sort's cost (all stages
// but the trace), the total's median / fastest, and the ratios unsorted /
// total (> 1: sorting wins) and unsorted / trace alone (what the order
// gains the trace).
//
// Environment: SORT_CHUNKS (work-items of the count and scatter passes,
// default 32), RTCL_BENCH_RES (image side, default 1024), RTCL_SCENES_DIR,
// RTCL_DEVICE.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "rtcl/accel/accel.hpp"
#include "rtcl/bench/ray_sets.hpp"
#include "rtcl/bench/scene_catalog.hpp"
#include "rtcl/cl/device.hpp"
#include "rtcl/error.hpp"
#include "rtcl/render/ray_order.hpp"
#include "rtcl/scene/geometry.hpp"

#include "../ab_support.hpp"

namespace {

using namespace rtcl;
using namespace rtcl::bench;

struct Key {
  int origin_bits = 0, direction_bits = 0;
  bool direction_high = false;
  std::size_t buckets() const { return std::size_t{1} << (3 * (origin_bits + direction_bits)); }
};

Key parse_key(const std::string& s) {
  Key k;
  int a = 0, b = 0;
  char c1 = 0, c2 = 0;
  if (std::sscanf(s.c_str(), "%c%d%c%d", &c1, &a, &c2, &b) != 4) throw Error("key '" + s + "': expected oNdM or dMoN");
  if (c1 == 'o' && c2 == 'd') {
    k.origin_bits = a;
    k.direction_bits = b;
  } else if (c1 == 'd' && c2 == 'o') {
    k.direction_bits = a;
    k.origin_bits = b;
    k.direction_high = true;
  } else {
    throw Error("key '" + s + "': expected oNdM or dMoN");
  }
  if (k.origin_bits < 0 || k.direction_bits < 0 || k.origin_bits + k.direction_bits > 5)
    throw Error("key '" + s + "': at most 5 bits per axis in all");
  return k;
}

// One key's device pipeline and its stage times (each stage's kernel time:
// count, offsets, scatter, trace, unsort; then the total).
struct Pipeline {
  std::string name;
  Key key;
  cl::Kernel count, offsets, scatter, unsort;
  cl::Buffer counts, sorted, order, sorted_hits;
  std::vector<std::vector<double>> ms = std::vector<std::vector<double>>(6);
};

int run(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: rtcl_ray_sort_ab SCENES ROUNDS KEY...  (e.g. bunny,sponza 7 o3d1 d1o3)\n");
    return 2;
  }
  const std::vector<std::string> scenes = split(argv[1]);
  const int rounds = parse_rounds(argv[2]);
  const std::vector<std::string> keys(argv + 3, argv + argc);
  const int res = bench_res(1024);
  const char* chunk_env = std::getenv("SORT_CHUNKS");
  const std::size_t chunks = chunk_env && *chunk_env ? std::strtoul(chunk_env, nullptr, 10) : 32;
  if (chunks < 1) throw Error("SORT_CHUNKS must be a positive number");
  std::vector<Key> parsed;
  for (const std::string& key : keys) parsed.push_back(parse_key(key));
  const std::string scenes_dir = scenes_dir_or(RTCL_RAY_SORT_AB_SCENES_DIR);

  Device device = Device::open();
  cl::CommandQueue& queue = device.queue();
  for (const std::string& scene_name : scenes) {
    const SceneSpec& spec = fixed_camera_scene(scene_name);
    Geometry geometry = spec_geometry(spec, scenes_dir);
    validate(geometry);
    const Aabb bounds = geometry.bounds();
    std::unique_ptr<Accel> accel = make_accel(device, "bvh", geometry);

    auto trace_into = [&](Query query, const std::vector<Ray>& rays, std::vector<Hit>& hits) {
      cl::Buffer r = device.upload(rays.data(), rays.size() * sizeof(Ray), "rays");
      cl::Buffer h = device.allocate(rays.size() * sizeof(Hit), "hits");
      accel->trace(query, r, h, rays.size()).wait();
      hits.resize(rays.size());
      queue.enqueueReadBuffer(h, CL_TRUE, 0, rays.size() * sizeof(Hit), hits.data());
    };
    std::vector<Ray> primary = primary_rays(spec.camera, res, res);
    std::vector<Hit> primary_hits;
    trace_into(Query::closest, primary, primary_hits);
    SecondaryRays secondary = secondary_rays(geometry, primary, primary_hits, spec.light);

    struct Set {
      const char* name;
      Query query;
      const std::vector<Ray>* rays;
    };
    const Set sets[] = {{"shadow", Query::any, &secondary.shadow}, {"diffuse", Query::closest, &secondary.diffuse}};
    for (const Set& set : sets) {
      const std::vector<Ray>& rays = *set.rays;
      const std::size_t n = rays.size();
      if (n == 0) {
        std::printf("%-8s %-8s no rays (no primary ray hit)\n", scene_name.c_str(), set.name);
        continue;
      }
      std::vector<Hit> reference;
      trace_into(set.query, rays, reference);
      cl::Buffer ray_buffer = device.upload(rays.data(), n * sizeof(Ray), "rays");
      cl::Buffer hit_buffer = device.allocate(n * sizeof(Hit), "hits");

      std::vector<std::uint32_t> host_order = morton_order(rays, bounds);
      std::vector<Ray> host_sorted = gather<Ray>(rays, host_order);
      cl::Buffer host_buffer = device.upload(host_sorted.data(), n * sizeof(Ray), "host-sorted rays");
      {
        std::vector<Hit> hits;
        trace_into(set.query, host_sorted, hits);
        hits = scatter<Hit>(hits, host_order);
        if (std::memcmp(hits.data(), reference.data(), n * sizeof(Hit)))
          std::printf("DIFFERS %s %s host morton\n", scene_name.c_str(), set.name);
      }

      std::vector<Pipeline> pipes;
      const auto count = static_cast<cl_uint>(n), chunk = static_cast<cl_uint>((n + chunks - 1) / chunks);
      const cl_float4 lo{{bounds.lower.x, bounds.lower.y, bounds.lower.z, 0.0f}};
      for (std::size_t k = 0; k < keys.size(); ++k) {
        Pipeline p;
        p.name = keys[k];
        p.key = parsed[k];
        std::vector<std::string> defines = {"RTCL_SORT_ORIGIN_BITS=" + std::to_string(p.key.origin_bits),
                                            "RTCL_SORT_DIRECTION_BITS=" + std::to_string(p.key.direction_bits)};
        if (p.key.direction_high) defines.push_back("RTCL_SORT_DIRECTION_HIGH");
        cl::Program program = device.program("bench/ray_sort.cl", defines);
        p.count = cl::Kernel(program, "ray_sort_count");
        p.offsets = cl::Kernel(program, "ray_sort_offsets");
        p.scatter = cl::Kernel(program, "ray_sort_scatter");
        p.unsort = cl::Kernel(program, "ray_sort_unsort_hits");
        p.counts = device.allocate(chunks * p.key.buckets() * sizeof(cl_uint), "counts");
        p.sorted = device.allocate(n * sizeof(Ray), "sorted rays");
        p.order = device.allocate(n * sizeof(cl_uint), "order");
        p.sorted_hits = device.allocate(n * sizeof(Hit), "sorted hits");
        const float cells = static_cast<float>(1u << p.key.origin_bits);
        const glm::vec3 extent = bounds.extent();
        const cl_float4 scale{{extent.x > 0 ? cells / extent.x : 0.0f, extent.y > 0 ? cells / extent.y : 0.0f,
                               extent.z > 0 ? cells / extent.z : 0.0f, 0.0f}};
        p.count.setArg(0, ray_buffer), p.count.setArg(1, count), p.count.setArg(2, chunk), p.count.setArg(3, lo);
        p.count.setArg(4, scale), p.count.setArg(5, p.counts);
        p.offsets.setArg(0, p.counts), p.offsets.setArg(1, static_cast<cl_uint>(chunks));
        p.scatter.setArg(0, ray_buffer), p.scatter.setArg(1, count), p.scatter.setArg(2, chunk);
        p.scatter.setArg(3, lo), p.scatter.setArg(4, scale), p.scatter.setArg(5, p.counts);
        p.scatter.setArg(6, p.sorted), p.scatter.setArg(7, p.order);
        p.unsort.setArg(0, p.sorted_hits), p.unsort.setArg(1, p.order), p.unsort.setArg(2, count);
        p.unsort.setArg(3, hit_buffer);
        pipes.push_back(std::move(p));
      }
      auto record = [](std::vector<std::vector<double>>& ms, const std::vector<cl::Event>& e) {
        double total = 0.0;
        for (std::size_t s = 0; s < 5; ++s) {
          double t = kernel_ms(e[s]);
          ms[s].push_back(t);
          total += t;
        }
        ms[5].push_back(total);
      };
      auto run_sorted = [&](Pipeline& p) {
        std::vector<cl::Event> e(5);
        queue.enqueueNDRangeKernel(p.count, cl::NullRange, cl::NDRange(chunks), cl::NDRange(1), nullptr, &e[0]);
        queue.enqueueNDRangeKernel(p.offsets, cl::NullRange, cl::NDRange(1), cl::NDRange(1), nullptr, &e[1]);
        queue.enqueueNDRangeKernel(p.scatter, cl::NullRange, cl::NDRange(chunks), cl::NDRange(1), nullptr, &e[2]);
        e[3] = accel->trace(set.query, p.sorted, p.sorted_hits, n, {e[2]});
        std::vector<cl::Event> after{e[3]};
        queue.enqueueNDRangeKernel(p.unsort, cl::NullRange, cl::NDRange((n + 63) / 64 * 64), cl::NDRange(64), &after,
                                   &e[4]);
        record(p.ms, e);
      };
      auto check = [&](const std::string& what) {
        std::vector<Hit> hits(n);
        queue.enqueueReadBuffer(hit_buffer, CL_TRUE, 0, n * sizeof(Hit), hits.data());
        std::size_t differ = 0;
        for (std::size_t i = 0; i < n; ++i) differ += std::memcmp(&hits[i], &reference[i], sizeof(Hit)) != 0;
        if (differ)
          std::printf("DIFFERS %s %s %s on %zu of %zu rays\n", scene_name.c_str(), set.name, what.c_str(), differ, n);
      };
      for (Pipeline& p : pipes) {
        run_sorted(p);
        check(p.name);
        for (auto& v : p.ms) v.clear();
      }

      std::vector<double> plain_ms, host_ms;
      const std::size_t variants = 2 + pipes.size();
      for (int r = 0; r < rounds; ++r)
        for (std::size_t j = 0; j < variants; ++j) {
          std::size_t v = (j + static_cast<std::size_t>(r)) % variants;
          if (v == 0)
            plain_ms.push_back(kernel_ms(accel->trace(set.query, ray_buffer, hit_buffer, n)));
          else if (v == 1)
            host_ms.push_back(kernel_ms(accel->trace(set.query, host_buffer, hit_buffer, n)));
          else
            run_sorted(pipes[v - 2]);
        }
      std::printf("%-8s %-8s %8zu rays | unsorted %7.2f / %7.2f ms | host morton trace %7.2f / %7.2f (x%.3f / x%.3f)\n",
                  scene_name.c_str(), set.name, n, median(plain_ms), fastest(plain_ms), median(host_ms),
                  fastest(host_ms), median(plain_ms) / median(host_ms), fastest(plain_ms) / fastest(host_ms));
      // Stages in ms; stage `trace` is the trace, the others the sort's cost.
      auto print = [&](const std::string& name, const std::vector<std::vector<double>>& ms, std::size_t trace) {
        std::printf("    %-5s stages", name.c_str());
        for (std::size_t s = 0; s < 5; ++s) std::printf(s == trace ? " [trace %7.2f]" : " %5.2f", median(ms[s]));
        std::printf(" | sort %5.2f | total %7.2f / %7.2f ms | total x%.3f / x%.3f | trace alone x%.3f / x%.3f\n",
                    median(ms[5]) - median(ms[trace]), median(ms[5]), fastest(ms[5]), median(plain_ms) / median(ms[5]),
                    fastest(plain_ms) / fastest(ms[5]), median(plain_ms) / median(ms[trace]),
                    fastest(plain_ms) / fastest(ms[trace]));
      };
      for (Pipeline& p : pipes) print(p.name, p.ms, 3);
      std::fflush(stdout);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return rtcl::bench::run_main("rtcl_ray_sort_ab", run, argc, argv); }
