#include "rtcl/accel/bsp.hpp"
#include "rtcl/accel/structure_kernels.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <thread>

#include "rtcl/error.hpp"
#include "rtcl/thread_pool.hpp"

namespace rtcl {

namespace {

constexpr std::size_t kParallelMin = 4096;

class BspBuilder {
 public:
  BspBuilder(const KdPrimitives& prims, int depth, int leaf_size, unsigned threads)
      : prims_(prims), max_depth_(depth), leaf_size_(static_cast<std::size_t>(leaf_size)),
        threads_(static_cast<int>(threads) - 1) {}

  // `budget`: the references this subtree may list (kKdReferenceBudget).
  std::unique_ptr<KdBuildNode> build(glm::dvec3 lower, glm::dvec3 upper, std::vector<std::uint32_t> ids,
                                     int depth, double budget) {
    auto node = std::make_unique<KdBuildNode>();
    int axis = depth % 3;
    // The midpoint as a float; a node too thin to split in float is a leaf.
    float split = static_cast<float>(0.5 * (lower[axis] + upper[axis]));
    if (depth >= max_depth_ || ids.size() <= leaf_size_ || !(split > lower[axis] && split < upper[axis])) {
      node->prims = std::move(ids);
      return node;
    }
    glm::dvec3 below_upper = upper, above_lower = lower;
    below_upper[axis] = split;
    above_lower[axis] = split;
    std::vector<std::uint32_t> below, above;
    glm::dvec3 cl, cu;
    for (std::uint32_t i : ids) {
      if (prims_.clip(i, lower, below_upper, &cl, &cu)) below.push_back(i);
      if (prims_.clip(i, above_lower, upper, &cl, &cu)) above.push_back(i);
    }
    // A leaf as well: a split that leaves every primitive on both sides
    // (a scene flat in the plane, primitives sharing a point on it), which
    // only doubles the lists, and one beyond the subtree's budget.
    double both = static_cast<double>(below.size() + above.size());
    if ((below.size() == ids.size() && above.size() == ids.size()) || both > budget) {
      node->prims = std::move(ids);
      return node;
    }
    node->axis = axis;
    node->split = split;
    ids = {};
    double below_budget = budget * static_cast<double>(below.size()) / both;
    double above_budget = budget * static_cast<double>(above.size()) / both;
    if (both >= kParallelMin && threads_.try_take()) {
      run_jobs(2, [&](unsigned job) {
        if (job == 0)
          node->above = build(above_lower, upper, std::move(above), depth + 1, above_budget);
        else
          node->below = build(lower, below_upper, std::move(below), depth + 1, below_budget);
      });
      threads_.give_back();
    } else {
      node->below = build(lower, below_upper, std::move(below), depth + 1, below_budget);
      node->above = build(above_lower, upper, std::move(above), depth + 1, above_budget);
    }
    return node;
  }

 private:
  const KdPrimitives& prims_;
  int max_depth_;
  std::size_t leaf_size_;
  KdThreads threads_;
};

}  // namespace

int bsp_depth(const BspConfig& config, std::size_t primitives) {
  if (config.depth > 0) return config.depth;
  double n = static_cast<double>(std::max<std::size_t>(primitives, 1));
  return std::clamp(static_cast<int>(std::lround(std::log2(n))) + 6, 1, kKdMaxDepth);
}

KdTree build_bsp(const Geometry& geometry, const BspConfig& config) {
  if (config.depth < 0 || config.depth > kKdMaxDepth)
    throw Error("bsp: depth must be in [0, " + std::to_string(kKdMaxDepth) + "] (the traversal stack), got " +
                std::to_string(config.depth));
  if (config.leaf_size < 1) throw Error("bsp: leaf must be >= 1, got " + std::to_string(config.leaf_size));
  KdPrimitives prims = kd_primitives(geometry, "bsp", config.max_alloc_bytes);
  int depth = bsp_depth(config, prims.size());
  unsigned threads = config.thread_count ? config.thread_count : std::max(1u, std::thread::hardware_concurrency());
  BspBuilder builder(prims, depth, config.leaf_size, threads);
  std::vector<std::uint32_t> all(prims.size());
  for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
  auto root = builder.build(prims.lower, prims.upper, std::move(all), 0,
                            kKdReferenceBudget * static_cast<double>(prims.size()));
  return flatten_kd_tree(prims, *root, "bsp",
                         "depth=" + std::to_string(depth) + ",leaf=" + std::to_string(config.leaf_size),
                         config.max_alloc_bytes, threads);
}

const StructureSpec& bsp_structure() {
  static const StructureSpec spec{
      "bsp", "axis-aligned BSP: midpoint splits, axis x->y->z by depth, [min,max] interval traversal",
      {{"depth", OptionType::integer, std::int64_t{0}, 0, kKdMaxDepth, false,
        "deepest leaf in splits, at most the traversal stack; 0: round(log2 N) + 6. Deeper cuts clusters finer "
        "for more nodes and more straddling references"},
       {"leaf", OptionType::integer, std::int64_t{BspConfig{}.leaf_size}, 1, 1024, false,
        "a node with at most this many primitives is a leaf: fewer test less per leaf for more nodes to walk"},
       occluder_run_option()}};
  return spec;
}

std::unique_ptr<Accel> make_bsp(const Device& device, const Geometry& geometry, const BspConfig& config,
                                const AccelConfig& accel_config) {
  return build_kd_accel(
      device, geometry, "bsp",
      [&](std::size_t max_alloc_bytes) {
        BspConfig limited = config;
        if (!limited.max_alloc_bytes) limited.max_alloc_bytes = max_alloc_bytes;
        return build_bsp(geometry, limited);
      },
      accel_config, KdTraversal::single, config.occluder_run);
}

std::unique_ptr<Accel> make_bsp_accel(const Device& device, const Geometry& geometry, const AccelConfig& config) {
  const AccelOptions& o = config.options;
  BspConfig bsp;
  bsp.depth = static_cast<int>(o.integer("depth"));
  bsp.leaf_size = static_cast<int>(o.integer("leaf"));
  bsp.occluder_run = static_cast<std::uint32_t>(o.integer("occluder_run"));
  return make_bsp(device, geometry, bsp, config);
}

}  // namespace rtcl
