// rtcl_tree_visits: how much of a BVH the bench/ rays meet, counted on the
// host (no timing, so no noise from a shared machine), for comparing trees
// of one scene built with different builders and options:
//
//   rtcl_tree_visits SCENES SPEC...      (e.g. sponza,sibenik bvh bvh-ploc bvh:presplit=16)
//
// SPEC is a BVH structure with its build options, as --accel takes them
// (bvh, bvh-ploc, bvh-packet). Per scene and tree it prints the wide
// nodes, the leaf blocks and their filled lanes, the tree's SAH cost (the
// surface area of every wide node's box x 0.5 plus every block's x 1,
// over the root's: the builder's cost model) with its two sums apart (the
// wide nodes and the blocks a line through the root box meets, on
// average), and, for the primary rays
// and the diffuse bounces of the bench/ camera ($RTCL_BENCH_RES, default
// 256), the wide nodes, blocks and triangles an ideal traversal of each
// ray's segment [tmin, t_hit] tests: every node and block whose box the
// segment meets (in double precision), as the SAH assumes, and the share of
// those wide nodes whose box test lets 0, 1, 2 and 3 or more children
// through (the branches a traversal takes after each node). t_hit is the
// first tree's closest hit, traced by its kernel on the default device.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/accel/bvh.hpp"
#include "rtcl/accel_options.hpp"
#include "rtcl/aabb.hpp"
#include "rtcl/bench/ray_sets.hpp"
#include "rtcl/bench/scene_catalog.hpp"
#include "rtcl/device.hpp"
#include "rtcl/error.hpp"

#include "../ab_support.hpp"

namespace {

using namespace rtcl;
using namespace rtcl::bench;

struct Visits {
  double nodes = 0, blocks = 0, triangles = 0;
  double entered[4] = {};  // wide nodes that let 0, 1, 2, 3 or more children through

  Visits& operator+=(const Visits& o) {
    nodes += o.nodes, blocks += o.blocks, triangles += o.triangles;
    for (int c = 0; c < 4; ++c) entered[c] += o.entered[c];
    return *this;
  }
};

// Whether the segment [tmin, t_end] of `ray` meets lane k's box of `node`
// (slab test in double; a zero direction component is inside or outside
// its slab for every t).
bool segment_meets(const Ray& ray, double t_end, const Bvh8Node& node, int k) {
  const double o[3] = {ray.ox, ray.oy, ray.oz}, d[3] = {ray.dx, ray.dy, ray.dz};
  double t0 = ray.tmin, t1 = t_end;
  for (int a = 0; a < 3; ++a) {
    const double lo = node.bounds[a][k], hi = node.bounds[3 + a][k];
    if (d[a] == 0.0) {
      if (o[a] < lo || o[a] > hi) return false;
      continue;
    }
    double near = (lo - o[a]) / d[a], far = (hi - o[a]) / d[a];
    if (near > far) std::swap(near, far);
    t0 = std::max(t0, near);
    t1 = std::min(t1, far);
  }
  return t0 <= t1;
}

Visits ideal_visits(const Bvh8& bvh, const Ray& ray, double t_end) {
  Visits v;
  std::vector<int> stack = {0};
  while (!stack.empty()) {
    const Bvh8Node& node = bvh.nodes[static_cast<std::size_t>(stack.back())];
    stack.pop_back();
    v.nodes += 1;
    int entered = 0;
    for (int k = 0; k < RTCL_BLOCK_WIDTH; ++k) {
      const rtcl_i32 child = node.child[k];
      if (child == RTCL_CHILD_EMPTY || !segment_meets(ray, t_end, node, k)) continue;
      ++entered;
      if (child >= 0) {
        stack.push_back(child);
        continue;
      }
      v.blocks += 1;
      if ((~child & 1) == 0) {  // a triangle block (RTCL_LEAF_TRIANGLES)
        const TriangleBlock& block = bvh.blocks.triangles[static_cast<std::size_t>(~child >> 1)];
        for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) v.triangles += block.prim[lane] >= 0;
      }
    }
    v.entered[std::min(entered, 3)] += 1;
  }
  return v;
}

// The wide tree's expected work for a line through the root box (the SAH's
// assumption): the wide nodes it visits (every node's box area, the root's
// included, over the root's) and the leaf blocks it tests (their boxes'
// areas over the root's); the builder's SAH cost, 0.5 x nodes + 1 x blocks;
// and the blocks' filled lanes. The first two are what Embree's BVH
// statistics (its device config verbose=3) print as the inner nodes' and
// leaves' SAH, with its cost factors of 1.
struct TreeCost {
  double node_visits = 0, block_tests = 0, lanes_per_block = 0;
  double sah() const { return 0.5 * node_visits + block_tests; }
};

TreeCost tree_cost(const Bvh8& bvh) {
  Aabb root;
  for (int k = 0; k < RTCL_BLOCK_WIDTH; ++k)
    if (bvh.nodes[0].child[k] != RTCL_CHILD_EMPTY) root.grow(bvh8_lane_box(bvh.nodes[0], k));
  const double root_area = root.area();
  double node_area = root_area, block_area = 0, blocks = 0, lanes = 0;
  for (const Bvh8Node& node : bvh.nodes)
    for (int k = 0; k < RTCL_BLOCK_WIDTH; ++k) {
      const rtcl_i32 child = node.child[k];
      if (child == RTCL_CHILD_EMPTY) continue;
      (child >= 0 ? node_area : block_area) += bvh8_lane_box(node, k).area();
      if (child < 0 && (~child & 1) == 0) {
        const TriangleBlock& block = bvh.blocks.triangles[static_cast<std::size_t>(~child >> 1)];
        blocks += 1;
        for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) lanes += block.prim[lane] >= 0;
      }
    }
  TreeCost cost;
  cost.node_visits = node_area / root_area;
  cost.block_tests = block_area / root_area;
  cost.lanes_per_block = blocks > 0 ? lanes / blocks : 0.0;
  return cost;
}

int run(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: rtcl_tree_visits SCENES SPEC...  (e.g. sponza bvh bvh-ploc bvh:presplit=16)\n");
    return 2;
  }
  const std::vector<std::string> scenes = split(argv[1]);
  const int res = bench_res(256);
  const std::string scenes_dir = scenes_dir_or(RTCL_TREE_VISITS_SCENES_DIR);
  Device device = Device::open();
  for (const std::string& scene_name : scenes) {
    const SceneSpec& spec = fixed_camera_scene(scene_name);
    Geometry geometry = spec_geometry(spec, scenes_dir);
    validate(geometry);

    std::vector<Ray> primary = primary_rays(spec.camera, res, res);
    const std::unique_ptr<Accel> accel = make_accel(device, argv[2], geometry);
    auto closest_hits = [&](const std::vector<Ray>& rays) {
      cl::Buffer ray_buffer = device.upload(rays.data(), rays.size() * sizeof(Ray), "rays");
      cl::Buffer hit_buffer = device.allocate(rays.size() * sizeof(Hit), "hits");
      accel->trace(Query::closest, ray_buffer, hit_buffer, rays.size()).wait();
      std::vector<Hit> hits(rays.size());
      device.queue().enqueueReadBuffer(hit_buffer, CL_TRUE, 0, rays.size() * sizeof(Hit), hits.data());
      return hits;
    };
    std::vector<Hit> primary_hits = closest_hits(primary);
    std::vector<Ray> diffuse = secondary_rays(geometry, primary, primary_hits, spec.light).diffuse;
    std::vector<Hit> diffuse_hits = closest_hits(diffuse);
    const struct {
      const char* name;
      const std::vector<Ray>& rays;
      const std::vector<Hit>& hits;
    } sets[] = {{"primary", primary, primary_hits}, {"diffuse", diffuse, diffuse_hits}};

    std::printf("%s, %d x %d primary rays, %zu diffuse bounces; per ray: wide nodes / blocks / triangles tested\n",
                scene_name.c_str(), res, res, diffuse.size());
    for (int s = 2; s < argc; ++s) {
      const AccelSpec accel_spec = parse_accel_spec(argv[s]);
      AccelConfig config;
      config.options = accel_spec.options;
      const BvhConfig bvh_config = resolve_bvh_config(structure_spec(accel_spec.name), config);
      const Bvh8 bvh = flatten_bvh8(build_binary_bvh(geometry, bvh_config), geometry, flatten_options(bvh_config));
      const TreeCost cost = tree_cost(bvh);
      std::printf("  %-22s %6zu nodes %6zu blocks %.2f lanes/block  SAH cost %6.2f (%.2f nodes + %.2f blocks)",
                  argv[s], bvh.nodes.size(), bvh.blocks.triangles.size(), cost.lanes_per_block, cost.sah(),
                  cost.node_visits, cost.block_tests);
      for (const auto& set : sets) {
        Visits total;
        for (std::size_t i = 0; i < set.rays.size(); ++i) {
          const double t_end = set.hits[i].prim >= 0 ? set.hits[i].t : set.rays[i].tmax;
          total += ideal_visits(bvh, set.rays[i], t_end);
        }
        const double n = static_cast<double>(set.rays.size());
        std::printf("  | %s %5.2f / %4.2f / %5.2f", set.name, total.nodes / n, total.blocks / n, total.triangles / n);
        std::printf(" (entering 0/1/2/3+: %.0f/%.0f/%.0f/%.0f%%)", 100 * total.entered[0] / total.nodes,
                    100 * total.entered[1] / total.nodes, 100 * total.entered[2] / total.nodes,
                    100 * total.entered[3] / total.nodes);
      }
      std::printf("\n");
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return rtcl::bench::run_main("rtcl_tree_visits", run, argc, argv); }
