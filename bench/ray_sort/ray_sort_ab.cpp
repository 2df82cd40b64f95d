// rtcl_ray_sort_ab: Coherence::scattered trace calls (the rays sorted on the
// device first, rtcl/accel/ray_sort.hpp) against Coherence::incoherent ones
// (traced as they come), in one process, launch by launch, on the bench/
// scenes' shadow and diffuse rays.
//
//   rtcl_ray_sort_ab SCENES ROUNDS [ACCEL]
//   e.g. rtcl_ray_sort_ab bunny,sponza 7 bvh
//
// Per ray set: the incoherent call's kernel time; the scattered call's
// passes (count, offsets, scatter: the sort) and its trace, each from its
// OpenCL event, and its span (the first pass's start to the trace's end:
// what `rtcl bench` times); and the incoherent call on the rays in the
// host's 60-bit Morton order (render/ray_order.hpp: the trace alone, the
// host sort untimed). The scattered call's hits are compared with the
// incoherent call's (bit for bit at closest hit; hit or miss at any hit,
// whose reported occluder may differ). Rounds alternate the variants, the
// order rotated each round. Prints medians / fastest and the ratios
// incoherent / scattered (> 1: sorting wins).
//
// Environment: RTCL_BENCH_RES (image side, default 1024), RTCL_SCENES_DIR,
// RTCL_DEVICE.
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/bench/ray_sets.hpp"
#include "rtcl/bench/scene_catalog.hpp"
#include "rtcl/device.hpp"
#include "rtcl/error.hpp"
#include "rtcl/render/ray_order.hpp"
#include "rtcl/geometry.hpp"

#include "../ab_support.hpp"

namespace {

using namespace rtcl;
using namespace rtcl::bench;

int run(int argc, char** argv) {
  if (argc < 3 || argc > 4) {
    std::fprintf(stderr, "usage: rtcl_ray_sort_ab SCENES ROUNDS [ACCEL]  (e.g. bunny,sponza 7 bvh)\n");
    return 2;
  }
  const std::vector<std::string> scenes = split(argv[1]);
  const int rounds = parse_rounds(argv[2]);
  const std::string accel_name = argc == 4 ? argv[3] : "bvh";
  const int res = bench_res(1024);
  const std::string scenes_dir = scenes_dir_or(RTCL_RAY_SORT_AB_SCENES_DIR);

  Device device = Device::open();
  cl::CommandQueue& queue = device.queue();
  for (const std::string& scene_name : scenes) {
    const SceneSpec& spec = fixed_camera_scene(scene_name);
    Geometry geometry = spec_geometry(spec, scenes_dir);
    validate(geometry);
    std::unique_ptr<Accel> accel =
        make_accel(device, accel_name, geometry, AccelConfig{Precision::robust, {}, ScatteredSort::always});
    if (!accel->sorts(Coherence::scattered))
      throw Error(accel_name + " on " + device.info().name + ": its scattered calls do not sort");

    auto trace_into = [&](Query query, const std::vector<Ray>& rays, std::vector<Hit>& hits, Coherence coherence) {
      cl::Buffer r = device.upload(rays.data(), rays.size() * sizeof(Ray), "rays");
      cl::Buffer h = device.allocate(rays.size() * sizeof(Hit), "hits");
      accel->trace(query, r, h, rays.size(), {}, coherence).wait();
      hits.resize(rays.size());
      queue.enqueueReadBuffer(h, CL_TRUE, 0, rays.size() * sizeof(Hit), hits.data());
    };
    std::vector<Ray> primary = primary_rays(spec.camera, res, res);
    std::vector<Hit> primary_hits;
    trace_into(Query::closest, primary, primary_hits, Coherence::incoherent);
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
      std::vector<Hit> reference, sorted_hits;
      trace_into(set.query, rays, reference, Coherence::incoherent);
      trace_into(set.query, rays, sorted_hits, Coherence::scattered);
      std::size_t differ = 0;
      for (std::size_t i = 0; i < n; ++i)
        differ += set.query == Query::closest ? std::memcmp(&sorted_hits[i], &reference[i], sizeof(Hit)) != 0
                                              : (sorted_hits[i].prim < 0) != (reference[i].prim < 0);
      if (differ) std::printf("DIFFERS %s %s on %zu of %zu rays\n", scene_name.c_str(), set.name, differ, n);

      cl::Buffer ray_buffer = device.upload(rays.data(), n * sizeof(Ray), "rays");
      cl::Buffer hit_buffer = device.allocate(n * sizeof(Hit), "hits");
      std::vector<Ray> host_sorted = gather<Ray>(rays, morton_order(rays, geometry.bounds()));
      cl::Buffer host_buffer = device.upload(host_sorted.data(), n * sizeof(Ray), "host-sorted rays");

      std::vector<double> plain_ms, host_ms, span, trace_ms, sort_ms;
      for (int r = 0; r < rounds; ++r)
        for (int j = 0; j < 3; ++j) {
          int v = (j + r) % 3;
          if (v == 0) {
            plain_ms.push_back(kernel_ms(accel->trace(set.query, ray_buffer, hit_buffer, n)));
          } else if (v == 1) {
            host_ms.push_back(kernel_ms(accel->trace(set.query, host_buffer, hit_buffer, n)));
          } else {
            cl::Event done = accel->trace(set.query, ray_buffer, hit_buffer, n, {}, Coherence::scattered);
            span.push_back(accel->last_call_ms(done));
            trace_ms.push_back(kernel_ms(done));
            sort_ms.push_back(span.back() - trace_ms.back());
          }
        }
      std::printf("%-8s %-8s %8zu rays | incoherent %7.2f / %7.2f ms | scattered %7.2f / %7.2f ms (sort %5.2f, "
                  "trace %7.2f) x%.3f / x%.3f | trace alone x%.3f | host Morton order, trace alone x%.3f\n",
                  scene_name.c_str(), set.name, n, median(plain_ms), fastest(plain_ms), median(span), fastest(span),
                  median(sort_ms), median(trace_ms), median(plain_ms) / median(span), fastest(plain_ms) / fastest(span),
                  median(plain_ms) / median(trace_ms), median(plain_ms) / median(host_ms));
      std::fflush(stdout);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return rtcl::bench::run_main("rtcl_ray_sort_ab", run, argc, argv); }
