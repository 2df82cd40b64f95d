// The work the mixed-volume BVH's filters remove, counted on the host (no
// timing, so no noise from a shared machine):
//   volume_visits/<scene>/<kind>/<costs>   for every 16th ray of the ray
//   set, the tests an ideal traversal of the ray's segment [tmin, t_hit]
//   runs (t_hit from the set's reference answers, tmax for a miss): a node
//   is tested when the segment meets its entering volume, as the SAH
//   assumes. Counters per ray: box tests (nodes), filter tests (nodes with
//   a filter where some box was hit, as kernels/accel/bvh.cl runs them) and
//   leaf blocks; cost = boxes + sum of c_K x filter tests + block_cost x
//   blocks, and cost_ratio against the same tree with boxes alone, with the
//   costs of <costs> (the builder's) and with the measured (default) ones
//   (cost_ratio_measured: what a trace should gain). The volumes are tested with the host copies of the
//   device's conservative tests (rtcl/bounds/volume_rays.hpp): box and
//   filter volume as one slab volume (k-DOP, OBB) or box and sphere.
// <costs> as in volume_choice_bench.cpp.
#include <benchmark/benchmark.h>

#include <cfloat>

#include "bench_scenes.hpp"
#include "rtcl/accel/bvh.hpp"
#include "rtcl/accel/bvh_volumes.hpp"
#include "rtcl/bounds/kdop.hpp"
#include "rtcl/bounds/volume_rays.hpp"

namespace rtcl::bench {
namespace {

struct Setting {
  const char* name;
  VolumeCosts costs;
};

const Setting visit_settings[] = {
    {"default", VolumeCosts{}},
    {"kdop=0", {64.0f, 0.0f, 64.0f, VolumeCosts{}.block}},
    {"obb=0", {64.0f, 64.0f, 0.0f, VolumeCosts{}.block}},
    {"all=0", {0.0f, 0.0f, 0.0f, VolumeCosts{}.block}},
};

struct Counts {
  double boxes = 0, filters[kFilterKinds] = {}, blocks = 0;
};

// Child lane's box as a 3-slab volume, followed by `extra` slabs.
SlabVolume lane_slabs(const Bvh8Node& node, int lane) {
  SlabVolume v{};
  v.count = 3;
  float reach = 0.0f;
  for (int a = 0; a < 3; ++a) {
    v.normal[a][a] = 1.0f;
    v.d_near[a] = node.bounds[a][lane];
    v.d_far[a] = node.bounds[3 + a][lane];
    reach += std::fmax(v.d_near[a] * v.d_near[a], v.d_far[a] * v.d_far[a]);
  }
  v.reach = std::sqrt(reach) * (1.0f + FLT_EPSILON);
  return v;
}

class Tester {
 public:
  Tester(const Bvh8& bvh, const BvhVolumeFilters& f) : bvh_(bvh), f_(f) {}

  void trace(const Ray& ray, Counts& c) const {
    std::vector<rtcl_i32> stack{0};
    while (!stack.empty()) {
      rtcl_i32 ref = stack.back();
      stack.pop_back();
      if (ref < 0) {
        c.blocks += 1;
        continue;
      }
      const Bvh8Node& node = bvh_.nodes[static_cast<std::size_t>(ref)];
      c.boxes += 1;
      bool hit[RTCL_BLOCK_WIDTH] = {};
      bool any = false;
      float t;
      for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
        if (node.child[lane] == RTCL_CHILD_EMPTY) continue;
        SlabVolume box = lane_slabs(node, lane);
        hit[lane] = intersect_slab_volume(&box, &ray, &t) != 0;
        any = any || hit[lane];
      }
      rtcl_i32 filter = f_.filter_of.empty() ? RTCL_FILTER_NONE : f_.filter_of[static_cast<std::size_t>(ref)];
      if (filter != RTCL_FILTER_NONE && any) {
        int kind = RTCL_FILTER_KIND(filter);
        c.filters[kind] += 1;
        for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane)
          if (hit[lane]) hit[lane] = filter_keeps(kind, RTCL_FILTER_INDEX(filter), node, lane, ray);
      }
      for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane)
        if (hit[lane]) stack.push_back(node.child[lane]);
    }
  }

 private:
  bool filter_keeps(int kind, rtcl_i32 index, const Bvh8Node& node, int lane, const Ray& ray) const {
    float t;
    auto i = static_cast<std::size_t>(index);
    if (kind == RTCL_FILTER_SPHERE) {
      const Bvh8Spheres& s = f_.spheres[i];
      if (s.r[lane] < 0.0f) return true;
      SphereVolume v{s.cx[lane], s.cy[lane], s.cz[lane], s.r[lane], 0.0f, {}};
      return intersect_sphere_volume(&v, &ray, &t) != 0;
    }
    SlabVolume v = lane_slabs(node, lane);
    if (kind == RTCL_FILTER_KDOP) {
      static const std::vector<glm::vec3> dirs = kdop_directions(7);
      for (int j = 0; j < RTCL_KDOP_FILTER_SLABS; ++j) {
        for (int a = 0; a < 3; ++a) v.normal[3 + j][a] = dirs[static_cast<std::size_t>(3 + j)][a];
        v.d_near[3 + j] = f_.kdops[i].d_near[j][lane];
        v.d_far[3 + j] = f_.kdops[i].d_far[j][lane];
      }
      v.count = 3 + RTCL_KDOP_FILTER_SLABS;
    } else {
      const Bvh8Obb& o = f_.obbs[i];
      for (int k = 0; k < 3; ++k) {
        for (int a = 0; a < 3; ++a) v.normal[3 + k][a] = o.axis[3 * k + a][lane];
        v.d_near[3 + k] = o.d_near[k][lane];
        v.d_far[3 + k] = o.d_far[k][lane];
      }
      v.count = 6;
    }
    return intersect_slab_volume(&v, &ray, &t) != 0;
  }

  const Bvh8& bvh_;
  const BvhVolumeFilters& f_;
};

Counts count(const Bvh8& bvh, const BvhVolumeFilters& f, const RaySet& rays) {
  Tester tester(bvh, f);
  Counts c;
  for (std::size_t r = 0; r < rays.rays.size(); ++r) {
    Ray ray = rays.rays[r];
    if (rays.reference[r].prim >= 0) ray.tmax = rays.reference[r].t;
    tester.trace(ray, c);
  }
  double n = static_cast<double>(rays.rays.size());
  c.boxes /= n;
  c.blocks /= n;
  for (double& x : c.filters) x /= n;
  return c;
}

double cost_of(const Counts& c, const VolumeCosts& k) {
  return c.boxes + k.sphere * c.filters[0] + k.kdop * c.filters[1] + k.obb * c.filters[2] + k.block * c.blocks;
}

void volume_visits(benchmark::State& state, const std::string& scene_name, RayKind kind, const Setting* setting) {
  try {
    auto scene = bench_scene(scene_name);
    Bvh8 bvh = flatten_bvh8(build_binary_bvh(scene->geometry), scene->geometry);
    RaySet rays = subset(scene->rays(kind), scene->rays(kind).rays.size() / 16);
    BvhVolumeFilters filters = choose_volume_filters(bvh, setting->costs, scene->geometry.source);
    for (auto _ : state) {
      Counts plain = count(bvh, BvhVolumeFilters{}, rays), mixed = count(bvh, filters, rays);
      state.counters["rays"] = static_cast<double>(rays.rays.size());
      state.counters["boxes"] = mixed.boxes;
      state.counters["boxes_plain"] = plain.boxes;
      state.counters["filters"] = mixed.filters[0] + mixed.filters[1] + mixed.filters[2];
      state.counters["blocks"] = mixed.blocks;
      state.counters["blocks_plain"] = plain.blocks;
      state.counters["cost_ratio"] = cost_of(mixed, setting->costs) / cost_of(plain, setting->costs);
      state.counters["cost_ratio_measured"] = cost_of(mixed, VolumeCosts{}) / cost_of(plain, VolumeCosts{});
      state.counters["predicted_ratio"] = filters.chosen_cost / filters.aabb_cost;
    }
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

[[maybe_unused]] const bool volume_visits_registered = [] {
  for (const char* scene : {"bunny", "sponza", "sibenik"})
    for (RayKind kind : {RayKind::primary, RayKind::diffuse})
      for (const Setting& setting : visit_settings)
        benchmark::RegisterBenchmark(
            (std::string("volume_visits/") + scene + "/" + ray_kind_name(kind) + "/" + setting.name).c_str(),
            volume_visits, std::string(scene), kind, &setting)
            ->Iterations(1)
            ->Unit(benchmark::kMillisecond);
  return true;
}();

}  // namespace
}  // namespace rtcl::bench
