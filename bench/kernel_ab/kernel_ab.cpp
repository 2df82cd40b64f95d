// rtcl_kernel_ab: two or more versions of the kernels/ tree timed against
// each other in one process, launch by launch, on the bench/ scenes' rays.
//
//   rtcl_kernel_ab SCENES ROUNDS KERNEL_DIR[#ACCEL_SPEC]...
//   e.g. rtcl_kernel_ab bunny,sponza,sibenik 15 /tmp/kernels-before kernels
//        rtcl_kernel_ab sponza 15 'kernels#bvh' 'kernels#bvh:node_cost=0.35'
//
// A version's ACCEL_SPEC (default $AB_ACCEL, else bvh) is the structure and
// its build options as `--accel` takes them, so build options are compared
// the same way as kernels (their hits may then differ in ties). The spec
// `embree-tree` is the bvh over Embree's binary SAH tree (rtcBuildBVH,
// embree_baseline.hpp) instead of rtcl's: the same flatten and kernels, so
// the two builders' trees are compared as traced.
//
// Each KERNEL_DIR is a copy of kernels/ (RTCL_KERNEL_DIR is set to it while
// its structure's programs are built; programs are cached by source, so
// versions of different directories never share one, versions of one
// directory do). Per scene (bench/ camera and light, image side
// $RTCL_BENCH_RES, default 512) it traces the primary rays and the shadow and
// diffuse rays spawned from the first version's primary hits, as bench/
// does. Per ray set: one launch per version whose hits are compared with the
// first version's, bit for bit (a line "DIFFERS" names the rays that are
// not; for any-hit rays only hit or miss must agree, another occluder is
// counted on a line "other occluders"); then ROUNDS rounds of one launch
// per version, the order rotated each round, and one Embree rtcIntersect1 /
// rtcOccluded1 trace of the same rays on all hardware threads when built
// with Embree (the bench/ framing: traversal only). Prints per version the
// median and fastest kernel time (OpenCL events), its ratio to the first
// version (> 1: faster) and to Embree (rtcl rays/s over Embree's).
// Versions measured in one process and alternating see the same machine: on
// shared, drifting machines their ratios hold where separate runs' do not.
//
// Environment: AB_ACCEL (structure, default bvh), AB_NO_EMBREE (set: no
// Embree), AB_SETS (the ray sets to time, e.g. "primary,shadow"; default
// all three), AB_MORTON_ORDER (set: every timed set traced, by every
// version and Embree, in the host's Morton order of render/ray_order.hpp
// instead of the camera's row order), AB_PACKET_TILES (set: the primary
// rays, and so the shadow and diffuse rays spawned from them, in rtcl
// bench's packet-tile order, render/ray_order.hpp's packet_tile_order,
// instead of row order), AB_REPEAT_RAYS (N in 1 .. 1024: every
// timed set's rays replaced by every N-th ray, each traced N times in a row,
// by every version and Embree: the same count of rays, whose caches and
// branch history then see each path N times), RTCL_BENCH_RES,
// RTCL_SCENES_DIR, RTCL_DEVICE.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/accel/bvh.hpp"
#include "rtcl/bench/ray_sets.hpp"
#include "rtcl/bench/scene_catalog.hpp"
#include "rtcl/device.hpp"
#include "rtcl/error.hpp"
#include "rtcl/render/ray_order.hpp"
#include "rtcl/geometry.hpp"

#include "../ab_support.hpp"
#ifdef RTCL_HAVE_EMBREE
#include "rtcl/bench/embree_baseline.hpp"
#endif

namespace {

using namespace rtcl;
using namespace rtcl::bench;

int run(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr,
                 "usage: rtcl_kernel_ab SCENES ROUNDS KERNEL_DIR[#ACCEL_SPEC]...  (e.g. bunny,sponza 15 old/ kernels/)\n");
    return 2;
  }
  const std::vector<std::string> scenes = split(argv[1]);
  const int rounds = parse_rounds(argv[2]);
  const char* accel_env = std::getenv("AB_ACCEL");
  const std::string accel_name = accel_env && *accel_env ? accel_env : "bvh";
  struct Version {
    std::string kernel_dir, accel_spec;
  };
  std::vector<Version> versions;
  for (int i = 3; i < argc; ++i) {
    const std::string arg = argv[i];
    const std::size_t hash = arg.find('#');
    if (hash == std::string::npos)
      versions.push_back({arg, accel_name});
    else
      versions.push_back({arg.substr(0, hash), arg.substr(hash + 1)});
  }
  const int res = bench_res(512);
  const std::string scenes_dir = scenes_dir_or(RTCL_KERNEL_AB_SCENES_DIR);
  const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  const char* sets_env = std::getenv("AB_SETS");
  const std::vector<std::string> timed_sets =
      split(sets_env && *sets_env ? sets_env : "primary,shadow,diffuse");
  for (const std::string& name : timed_sets)
    if (name != "primary" && name != "shadow" && name != "diffuse")
      throw Error("AB_SETS: unknown ray set '" + name + "' (known: primary, shadow, diffuse)");
  const bool morton = std::getenv("AB_MORTON_ORDER") != nullptr;
  const bool packet_tiles = std::getenv("AB_PACKET_TILES") != nullptr;
  const char* repeat_env = std::getenv("AB_REPEAT_RAYS");
  const int repeat = repeat_env && *repeat_env ? std::atoi(repeat_env) : 1;
  if (repeat < 1 || repeat > 1024)
    throw Error(std::string("AB_REPEAT_RAYS must be a number in 1 .. 1024, not '") + repeat_env + "'");
#ifdef RTCL_HAVE_EMBREE
  const bool use_embree = std::getenv("AB_NO_EMBREE") == nullptr;
#endif

  Device device = Device::open();
  for (const std::string& scene_name : scenes) {
    const SceneSpec& spec = fixed_camera_scene(scene_name);
    Geometry geometry = spec_geometry(spec, scenes_dir);
    validate(geometry);

    std::vector<std::unique_ptr<Accel>> accels;
    for (const Version& version : versions) {
      setenv("RTCL_KERNEL_DIR", version.kernel_dir.c_str(), 1);
      if (version.accel_spec == "embree-tree") {
#ifdef RTCL_HAVE_EMBREE
        BvhConfig config;
        config.custom_builder = [threads](std::span<const Aabb> bounds, std::span<const std::uint32_t> ids) {
          return embree_binary_tree(bounds, ids, threads);
        };
        accels.push_back(make_bvh(device, geometry, config));
#else
        throw Error("version spec 'embree-tree': rtcl_kernel_ab was built without Embree");
#endif
      } else {
        accels.push_back(make_accel(device, version.accel_spec, geometry));
      }
    }
    // One launch of version v over `rays`; its hits into *hits when given.
    auto launch = [&](std::size_t v, Query query, const std::vector<Ray>& rays, std::vector<Hit>* hits) {
      setenv("RTCL_KERNEL_DIR", versions[v].kernel_dir.c_str(), 1);
      cl::Buffer ray_buffer = device.upload(rays.data(), rays.size() * sizeof(Ray), "rays");
      cl::Buffer hit_buffer = device.allocate(rays.size() * sizeof(Hit), "hits");
      accels[v]->trace(query, ray_buffer, hit_buffer, rays.size()).wait();
      hits->resize(rays.size());
      device.queue().enqueueReadBuffer(hit_buffer, CL_TRUE, 0, rays.size() * sizeof(Hit), hits->data());
    };

    std::vector<Ray> primary = primary_rays(spec.camera, res, res);
    if (packet_tiles) primary = gather<Ray>(primary, packet_tile_order(res, res));
    std::vector<Hit> primary_hits;
    launch(0, Query::closest, primary, &primary_hits);
    SecondaryRays secondary = secondary_rays(geometry, primary, primary_hits, spec.light);
    struct Set {
      const char* name;
      Query query;
      const std::vector<Ray>* rays;
    };
    const Set sets[] = {{"primary", Query::closest, &primary},
                        {"shadow", Query::any, &secondary.shadow},
                        {"diffuse", Query::closest, &secondary.diffuse}};
#ifdef RTCL_HAVE_EMBREE
    std::unique_ptr<EmbreeScene> embree;
    if (use_embree) embree = std::make_unique<EmbreeScene>(geometry, EmbreeQuality::standard, threads);
#endif
    for (const Set& set : sets) {
      if (std::find(timed_sets.begin(), timed_sets.end(), set.name) == timed_sets.end()) continue;
      std::vector<Ray> rays = *set.rays;
      if (morton) rays = gather<Ray>(rays, morton_order(rays, geometry.bounds()));
      for (std::size_t i = 0; i < rays.size(); ++i) rays[i] = rays[i - i % static_cast<std::size_t>(repeat)];
      std::vector<Hit> first, other;
      launch(0, set.query, rays, &first);
      for (std::size_t v = 1; v < versions.size(); ++v) {
        launch(v, set.query, rays, &other);
        std::size_t differ = 0, hit_or_miss = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
          differ += std::memcmp(&first[i], &other[i], sizeof(Hit)) != 0;
          hit_or_miss += (first[i].prim < 0) != (other[i].prim < 0);
        }
        // An any-hit query may report another occluder: only hit or miss must agree.
        if (set.query == Query::any ? hit_or_miss != 0 : differ != 0)
          std::printf("DIFFERS %s %s: version %zu on %zu of %zu rays (%zu hit or miss)\n", scene_name.c_str(),
                      set.name, v, differ, rays.size(), hit_or_miss);
        else if (differ)
          std::printf("other occluders %s %s: version %zu on %zu of %zu rays, hit or miss the same\n",
                      scene_name.c_str(), set.name, v, differ, rays.size());
      }
      cl::Buffer ray_buffer = device.upload(rays.data(), rays.size() * sizeof(Ray), "rays");
      cl::Buffer hit_buffer = device.allocate(rays.size() * sizeof(Hit), "hits");
      std::vector<std::vector<double>> ms(versions.size());
      std::vector<double> embree_ms;
      for (int r = 0; r < rounds; ++r) {
        for (std::size_t j = 0; j < versions.size(); ++j) {
          std::size_t v = (j + static_cast<std::size_t>(r)) % versions.size();
          ms[v].push_back(kernel_ms(accels[v]->trace(set.query, ray_buffer, hit_buffer, rays.size())));
        }
#ifdef RTCL_HAVE_EMBREE
        if (embree) {
          embree->prepare(set.query, rays.data(), rays.size());
          auto start = std::chrono::steady_clock::now();
          embree->trace_prepared(threads);
          embree_ms.push_back(
              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
        }
#endif
      }
      std::printf("%-8s %-8s %8zu rays |", scene_name.c_str(), set.name, rays.size());
      for (std::size_t v = 0; v < versions.size(); ++v) {
        std::printf(" v%zu %7.2f / %7.2f ms", v, median(ms[v]), fastest(ms[v]));
        if (v) std::printf(" (x%.3f / x%.3f)", median(ms[0]) / median(ms[v]), fastest(ms[0]) / fastest(ms[v]));
        if (!embree_ms.empty())
          std::printf(" E %.3f / %.3f", median(embree_ms) / median(ms[v]), fastest(embree_ms) / fastest(ms[v]));
        std::printf(" |");
      }
      if (!embree_ms.empty()) std::printf(" embree %7.2f / %7.2f ms", median(embree_ms), fastest(embree_ms));
      std::printf("\n");
      std::fflush(stdout);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return rtcl::bench::run_main("rtcl_kernel_ab", run, argc, argv); }
