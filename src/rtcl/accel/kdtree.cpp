#include "rtcl/accel/kdtree.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <thread>

#include "rtcl/error.hpp"

namespace rtcl {

namespace {

constexpr std::size_t kParallelMin = 4096;

// A boundary event of a primitive's clipped bounds on one axis (Wald &
// Havran 2006, section 4.2): its lower end (start), its upper end (end), or
// both at once for bounds flat on the axis (planar). Sorted by position,
// then end < planar < start, which is the order the sweep needs: at a
// candidate plane p the primitives ending at p are left of it, those
// starting at p right of it.
enum EventType : std::uint8_t { kEnd = 0, kPlanar = 1, kStart = 2 };

struct Event {
  float pos;
  std::uint32_t prim;
  std::uint8_t type;
  bool operator<(const Event& o) const { return pos < o.pos || (pos == o.pos && type < o.type); }
};

using Events = std::array<std::vector<Event>, 3>;

// Event positions enclose the double-precision bounds.
void add_events(Events& events, std::uint32_t prim, const glm::dvec3& lower, const glm::dvec3& upper) {
  for (int k = 0; k < 3; ++k) {
    float lo = kd_round_float(lower[k], true), hi = kd_round_float(upper[k], false);
    if (lo == hi) {
      events[k].push_back({lo, prim, kPlanar});
    } else {
      events[k].push_back({lo, prim, kStart});
      events[k].push_back({hi, prim, kEnd});
    }
  }
}

struct Split {
  int axis = -1;
  float pos = 0.0f;
  double cost = 0.0;
  std::size_t n_below = 0, n_above = 0;  // primitives each side lists
};

// Primitive sides during one split (bit 0: below, bit 1: above).
enum Side : std::uint8_t { kBelow = 1, kAbove = 2, kBoth = 3 };

class KdBuilder {
 public:
  KdBuilder(const KdPrimitives& prims, const KdTreeConfig& config, int depth, unsigned threads)
      : prims_(prims), config_(config), max_depth_(depth), threads_(static_cast<int>(threads) - 1) {}

  // `budget`: the references this subtree may list (kKdReferenceBudget).
  std::unique_ptr<KdBuildNode> build(const glm::dvec3& lower, const glm::dvec3& upper, Events events, int depth,
                                     double budget, std::vector<std::uint8_t>& side) {
    auto node = std::make_unique<KdBuildNode>();
    std::size_t n = 0;
    for (const Event& e : events[0]) n += e.type != kEnd;
    Split split;
    if (depth < max_depth_ && n > 0) split = find_split(lower, upper, events, n);
    const int k = split.axis;
    const float p = split.pos;
    std::size_t n_below = 0, n_above = 0;
    if (k >= 0) {
      n_below = split.n_below;
      n_above = split.n_above;
    }
    double both = static_cast<double>(n_below + n_above);
    if (k < 0 || both > budget) {
      for (const Event& e : events[0])
        if (e.type != kEnd) node->prims.push_back(e.prim);
      std::sort(node->prims.begin(), node->prims.end());
      return node;
    }
    node->axis = k;
    node->split = p;
    // Sides, as the sweep counted them: below when the bounds start before
    // p, above when they end after it, both for bounds flat on p. Bounds
    // ending exactly at p are below only (event positions are rounded
    // outwards, so the primitive does not reach beyond p), starting at p
    // above only. Widening here would list a primitive ending at p as a
    // sliver on the far side, which the SAH cuts around again and again.
    for (const Event& e : events[k]) {
      if (e.type == kPlanar && e.pos == p) {
        side[e.prim] = kBoth;
        continue;
      }
      if (e.type != kEnd && e.pos < p) side[e.prim] |= kBelow;
      if (e.type != kStart && e.pos > p) side[e.prim] |= kAbove;
    }
    glm::dvec3 below_upper = upper, above_lower = lower;
    below_upper[k] = p;
    above_lower[k] = p;
    Events below, above, below_new, above_new;
    for (int a = 0; a < 3; ++a) {
      below[a].reserve(events[a].size());
      above[a].reserve(events[a].size());
      for (const Event& e : events[a]) {
        if (side[e.prim] == kBelow) below[a].push_back(e);
        else if (side[e.prim] == kAbove) above[a].push_back(e);
      }
    }
    // Straddling primitives: clipped again to each child (perfect splits;
    // one that does not reach a child is dropped from it).
    glm::dvec3 cl, cu;
    for (const Event& e : events[k]) {
      if (e.type == kEnd) continue;
      if (side[e.prim] == kBoth) {
        if (prims_.clip(e.prim, lower, below_upper, &cl, &cu)) add_events(below_new, e.prim, cl, cu);
        if (prims_.clip(e.prim, above_lower, upper, &cl, &cu)) add_events(above_new, e.prim, cl, cu);
      }
      side[e.prim] = 0;
    }
    events = {};
    for (int a = 0; a < 3; ++a) {
      merge_in(below[a], below_new[a]);
      merge_in(above[a], above_new[a]);
    }
    below_new = {};
    above_new = {};
    // The children's shares of the budget, from the sweep's counts (an
    // upper bound of what the clipping keeps).
    double below_budget = budget * static_cast<double>(n_below) / both;
    double above_budget = budget * static_cast<double>(n_above) / both;
    if (n >= kParallelMin && threads_.try_take()) {
      std::thread worker([&] {
        std::vector<std::uint8_t> own(prims_.size(), 0);
        node->below = build(lower, below_upper, std::move(below), depth + 1, below_budget, own);
      });
      node->above = build(above_lower, upper, std::move(above), depth + 1, above_budget, side);
      worker.join();
      threads_.give_back();
    } else {
      node->below = build(lower, below_upper, std::move(below), depth + 1, below_budget, side);
      node->above = build(above_lower, upper, std::move(above), depth + 1, above_budget, side);
    }
    return node;
  }

 private:
  static void merge_in(std::vector<Event>& into, std::vector<Event>& added) {
    if (added.empty()) return;
    std::sort(added.begin(), added.end());
    std::size_t middle = into.size();
    into.insert(into.end(), added.begin(), added.end());
    std::inplace_merge(into.begin(), into.begin() + static_cast<std::ptrdiff_t>(middle), into.end());
  }

  // Intersection tests a leaf of n primitives costs: one per batch of
  // config.batch (the kernel tests up to 8 at once in float8 lanes).
  double tests(std::size_t n) const {
    return static_cast<double>(config_.batch == 1 ? n : (n + config_.batch - 1) / config_.batch);
  }

  // The sweep over each axis's sorted events (Wald & Havran 2006,
  // algorithm 4): N_L, N_P, N_R at every event position strictly inside
  // the node. Planar primitives at the plane count on both sides (the
  // build lists them on both). Returns axis -1 when no split beats a leaf.
  Split find_split(const glm::dvec3& lower, const glm::dvec3& upper, const Events& events, std::size_t n) const {
    glm::dvec3 e = upper - lower;
    double area = 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
    Split best;
    best.cost = config_.intersection_cost * tests(n);
    if (!(area > 0.0)) return best;
    // cost = ct + ci / area * (area_below * N_below + area_above * N_above)
    const double scale = config_.intersection_cost / area;
    for (int k = 0; k < 3; ++k) {
      int a = (k + 1) % 3, b = (k + 2) % 3;
      double cross = 2.0 * e[a] * e[b], perimeter = 2.0 * (e[a] + e[b]);
      std::size_t left = 0, right = n;
      const std::vector<Event>& list = events[k];
      for (std::size_t i = 0; i < list.size();) {
        float p = list[i].pos;
        std::size_t ending = 0, planar = 0, starting = 0;
        while (i < list.size() && list[i].pos == p && list[i].type == kEnd) ++ending, ++i;
        while (i < list.size() && list[i].pos == p && list[i].type == kPlanar) ++planar, ++i;
        while (i < list.size() && list[i].pos == p && list[i].type == kStart) ++starting, ++i;
        right -= planar + ending;
        if (p > lower[k] && p < upper[k]) {
          std::size_t n_below = left + planar, n_above = right + planar;
          double area_below = cross + (p - lower[k]) * perimeter;
          double area_above = cross + (upper[k] - p) * perimeter;
          double cost =
              config_.traversal_cost + scale * (area_below * tests(n_below) + area_above * tests(n_above));
          if (n_below == 0 || n_above == 0) cost *= 1.0 - config_.empty_bonus;
          if (cost < best.cost) best = {k, p, cost, n_below, n_above};
        }
        left += starting + planar;
      }
    }
    return best;
  }

  const KdPrimitives& prims_;
  const KdTreeConfig& config_;
  int max_depth_;
  KdThreads threads_;
};

void check_config(const KdTreeConfig& c) {
  if (c.depth < 0 || c.depth > kKdMaxDepth)
    throw Error("kdtree: depth must be in [0, " + std::to_string(kKdMaxDepth) + "] (the traversal stack), got " +
                std::to_string(c.depth));
  if (!(c.traversal_cost > 0.0) || !std::isfinite(c.traversal_cost))
    throw Error("kdtree: ct must be > 0 (got " + std::to_string(c.traversal_cost) + ")");
  if (!(c.intersection_cost > 0.0) || !std::isfinite(c.intersection_cost))
    throw Error("kdtree: ci must be > 0 (got " + std::to_string(c.intersection_cost) + ")");
  if (!(c.empty_bonus >= 0.0 && c.empty_bonus < 1.0))
    throw Error("kdtree: empty must be in [0, 1) (got " + std::to_string(c.empty_bonus) + ")");
  if (c.batch < 1 || c.batch > 8) throw Error("kdtree: batch must be in [1, 8] (got " + std::to_string(c.batch) + ")");
}

}  // namespace

int kdtree_depth(const KdTreeConfig& config, std::size_t primitives) {
  if (config.depth > 0) return config.depth;
  double n = static_cast<double>(std::max<std::size_t>(primitives, 1));
  return std::clamp(static_cast<int>(std::lround(8.0 + 1.3 * std::log2(n))), 1, kKdMaxDepth);
}

KdTree build_kdtree(const Geometry& geometry, const KdTreeConfig& config) {
  check_config(config);
  KdPrimitives prims = kd_primitives(geometry, "kdtree", config.max_alloc_bytes);
  int depth = kdtree_depth(config, prims.size());
  unsigned threads = config.thread_count ? config.thread_count : std::max(1u, std::thread::hardware_concurrency());
  // The root's events from the primitives' own bounds (the root box holds
  // them all), sorted once: every node below keeps its lists sorted.
  Events events;
  for (auto& list : events) list.reserve(2 * prims.size());
  for (std::uint32_t i = 0; i < prims.size(); ++i) {
    glm::dvec3 lo, hi;
    prims.bounds(i, &lo, &hi);
    add_events(events, i, lo, hi);
  }
  if (threads > 1 && prims.size() >= kParallelMin) {
    std::thread y([&] { std::sort(events[1].begin(), events[1].end()); });
    std::sort(events[0].begin(), events[0].end());
    std::sort(events[2].begin(), events[2].end());
    y.join();
  } else {
    for (auto& list : events) std::sort(list.begin(), list.end());
  }
  KdBuilder builder(prims, config, depth, threads);
  std::vector<std::uint8_t> side(prims.size(), 0);
  auto root = builder.build(prims.lower, prims.upper, std::move(events), 0,
                            kKdReferenceBudget * static_cast<double>(prims.size()), side);
  return flatten_kd_tree(prims, *root, "kdtree", "depth=" + std::to_string(depth), config.max_alloc_bytes);
}

namespace {

std::vector<OptionSpec> kdtree_options() {
  static const KdTreeConfig d;
  return {{"depth", OptionType::integer, std::int64_t{0}, 0, kKdMaxDepth, false,
           "deepest leaf in splits, at most the traversal stack; 0: round(8 + 1.3 log2 N)"},
          {"ct", OptionType::real, d.traversal_cost, 0, 1e6, true,
           "SAH cost of one node step: higher makes shallower trees with larger leaves"},
          {"ci", OptionType::real, d.intersection_cost, 0, 1e6, true,
           "SAH cost of one primitive test: higher makes deeper trees with smaller leaves"},
          {"empty", OptionType::real, d.empty_bonus, 0, 0.99, false,
           "empty-space bonus: a split with one empty side costs (1 - empty) times its SAH cost"},
          {"batch", OptionType::integer, std::int64_t{d.batch}, 1, 8, false,
           "primitives per intersection test in the SAH (1: classic; 8: the kernel's float8 batch, larger leaves)"}};
}

std::unique_ptr<Accel> make_kdtree_from(const StructureSpec& spec, KdTraversal traversal, const Device& device,
                                        const Geometry& geometry, const AccelConfig& config) {
  AccelOptions o = resolve_options(spec, config.options, "--accel " + spec.name);
  KdTreeConfig kd;
  kd.depth = static_cast<int>(o.integer("depth"));
  kd.traversal_cost = o.real("ct");
  kd.intersection_cost = o.real("ci");
  kd.empty_bonus = o.real("empty");
  kd.batch = static_cast<unsigned>(o.integer("batch"));
  return make_kdtree(device, geometry, kd, config, spec.name, traversal);
}

}  // namespace

const StructureSpec& kdtree_structure() {
  static const StructureSpec spec{
      "kdtree",
      "SAH kd-tree: O(N log N) sorted-event build, perfect splits, [min,max] interval traversal; packets of 8 rays "
      "for coherent calls",
      kdtree_options()};
  return spec;
}

const StructureSpec& kdtree_packet_structure() {
  static const StructureSpec spec{"kdtree-packet", "the kdtree, always traced in packets of 8 rays (for measuring)",
                                  kdtree_options()};
  return spec;
}

std::unique_ptr<Accel> make_kdtree(const Device& device, const Geometry& geometry, const KdTreeConfig& config,
                                   const AccelConfig& accel_config, const std::string& name, KdTraversal traversal) {
  return build_kd_accel(
      device, geometry, name,
      [&](std::size_t max_alloc_bytes) {
        KdTreeConfig limited = config;
        if (!limited.max_alloc_bytes) limited.max_alloc_bytes = max_alloc_bytes;
        return build_kdtree(geometry, limited);
      },
      accel_config, traversal);
}

std::unique_ptr<Accel> make_kdtree_accel(const Device& device, const Geometry& geometry,
                                         const AccelConfig& config) {
  return make_kdtree_from(kdtree_structure(), KdTraversal::by_coherence, device, geometry, config);
}

std::unique_ptr<Accel> make_kdtree_packet_accel(const Device& device, const Geometry& geometry,
                                                const AccelConfig& config) {
  return make_kdtree_from(kdtree_packet_structure(), KdTraversal::packet, device, geometry, config);
}

}  // namespace rtcl
