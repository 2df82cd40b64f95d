#include "rtcl/accel/octree_r.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "rtcl/error.hpp"

namespace rtcl {

float octree_r_split(double lo, double hi, double e1, double e2, const std::vector<double>& prim_lower,
                     const std::vector<double>& prim_upper, int bins) {
  double centre = 0.5 * (lo + hi), width = hi - lo;
  if (!(width > 0.0) || bins < 2) return static_cast<float>(centre);
  // starts[b]: primitives whose clipped lower end falls in bin b, ends[b]:
  // whose upper end does; bin b is [lo + b w, lo + (b + 1) w).
  std::vector<std::size_t> starts(bins, 0), ends(bins, 0);
  auto bin = [&](double x) {
    return std::clamp(static_cast<int>(std::floor((x - lo) / width * bins)), 0, bins - 1);
  };
  for (std::size_t i = 0; i < prim_lower.size(); ++i) {
    ++starts[bin(std::max(prim_lower[i], lo))];
    ++ends[bin(std::min(prim_upper[i], hi))];
  }
  auto area = [&](double w) { return 2.0 * (w * e1 + w * e2 + e1 * e2); };
  double best_cost = std::numeric_limits<double>::infinity(), best = centre;
  std::size_t left = 0, right = prim_lower.size();
  for (int j = 1; j < bins; ++j) {
    // plane p_j = lo + j w: left holds lower ends below it, right drops
    // the primitives whose upper end lies below it
    left += starts[j - 1];
    right -= ends[j - 1];
    double p = lo + width * j / bins;
    double cost = area(p - lo) * double(left) + area(hi - p) * double(right);
    if (cost < best_cost || (cost == best_cost && std::fabs(p - centre) < std::fabs(best - centre))) {
      best_cost = cost;
      best = p;
    }
  }
  float split = static_cast<float>(best);
  return std::clamp(split, static_cast<float>(lo), static_cast<float>(hi));
}

OctreePtr build_octree_r(const Geometry& geometry, const OctreeRConfig& config) {
  OctreeBuildConfig build = octree_build_config(config, "octree-r");
  build.split_cost = config.traversal_cost;
  check_octree_config(build, kOctreePtrMaxDepth);
  if (!(config.traversal_cost > 0.0) || !std::isfinite(config.traversal_cost))
    throw Error("octree-r: traversal_cost=" + std::to_string(config.traversal_cost) + ": must be > 0");
  if (config.bins < 2 || config.bins > 1024)
    throw Error("octree-r: bins=" + std::to_string(config.bins) + ": must be in [2, 1024]");
  // The root: the scene's padded box, rounded outwards (not a cube: free
  // planes need none).
  Aabb box = geometry.bounds();
  double pad = octree_padding(geometry);
  std::array<float, 3> lower, upper;
  for (int a = 0; a < 3; ++a) {
    lower[a] = std::nextafter(static_cast<float>(box.lower[a] - pad), -std::numeric_limits<float>::infinity());
    upper[a] = std::nextafter(static_cast<float>(box.upper[a] + pad), std::numeric_limits<float>::infinity());
  }
  int bins = config.bins;
  OctreeSplitRule rule = [bins](const OctreeBuildNode& node, const std::vector<rtcl_i32>& refs,
                                const PrimitiveBounds& bounds) {
    std::array<float, 3> split{};
    std::vector<double> pl(refs.size()), pu(refs.size());
    for (int a = 0; a < 3; ++a) {
      for (std::size_t i = 0; i < refs.size(); ++i) {
        std::size_t k = bounds.index(refs[i]);
        pl[i] = bounds.lower[k][a];
        pu[i] = bounds.upper[k][a];
      }
      double e1 = double(node.upper[(a + 1) % 3]) - node.lower[(a + 1) % 3];
      double e2 = double(node.upper[(a + 2) % 3]) - node.lower[(a + 2) % 3];
      split[a] = octree_r_split(node.lower[a], node.upper[a], e1, e2, pl, pu, bins);
    }
    return split;
  };
  return flatten_octree_ptr(geometry, build_octree_nodes(geometry, lower, upper, build, kOctreePtrMaxDepth, rule),
                            lower, upper);
}

std::unique_ptr<Accel> make_octree_r(const Device& device, const Geometry& geometry, const OctreeRConfig& config,
                                     const AccelConfig& accel_config) {
  AccelStats stats;
  OctreePtr tree = timed_octree_build(device, geometry, config, build_octree_r, &stats);
  return make_octree_ptr_from(device, geometry, "octree-r", tree, config.occluder_run, stats, accel_config);
}

const StructureSpec& octree_r_structure() {
  static const StructureSpec spec{
      "octree-r",
      "Octree-R (Whang et al. 1995): split planes per axis chosen by area x count cost, pointer traversal",
      octree_options(
          kOctreePtrMaxDepth, OctreeRConfig{}.max_depth, OctreeRConfig{}.leaf_size, OctreeRConfig{}.ref_budget,
          {{"bins", OptionType::integer, std::int64_t(OctreeRConfig{}.bins), 2, 1024, false,
            "candidate split planes per axis and node, plus one: more find cheaper planes at a longer build"},
           {"traversal_cost", OptionType::real, OctreeRConfig{}.traversal_cost, 0, 1000, true,
            "cost of a traversal step in primitive tests: a node is split only when that lowers its estimated "
            "cost; higher makes shallower trees with longer leaves"}})};
  return spec;
}

std::unique_ptr<Accel> make_octree_r_accel(const Device& device, const Geometry& geometry,
                                           const AccelConfig& config) {
  const AccelOptions& o = config.options;
  OctreeRConfig tree;
  read_octree_options(o, &tree);
  tree.bins = static_cast<int>(o.integer("bins"));
  tree.traversal_cost = o.real("traversal_cost");
  return make_octree_r(device, geometry, tree, config);
}

}  // namespace rtcl
