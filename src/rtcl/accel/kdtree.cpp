#include "rtcl/accel/kdtree.hpp"
#include "rtcl/accel/structure_kernels.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <limits>
#include <mutex>
#include <string>
#include <thread>

#include "rtcl/error.hpp"
#include "rtcl/thread_pool.hpp"

namespace rtcl {

namespace {

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

// A primitive's bounds clipped to a node's (widened) box, rounded outwards
// to float: what both the binned and the exact split see of it.
struct Ref {
  std::array<float, 3> lower, upper;
  std::uint32_t prim;
};

// Four floats in one vector register (GCC/Clang vector extensions), for
// binning a bound's three coordinates at once.
using Float4 = float __attribute__((vector_size(16)));
using Int4 = std::int32_t __attribute__((vector_size(16)));

// The four floats from xyz on: a Ref's lower or upper bound and the float
// after it (lane 3, within the Ref either way).
Float4 load4(const float* xyz) {
  Float4 v;
  std::memcpy(&v, xyz, sizeof v);
  return v;
}

Ref make_ref(std::uint32_t prim, const glm::dvec3& lower, const glm::dvec3& upper) {
  Ref r;
  r.prim = prim;
  for (int k = 0; k < 3; ++k) {
    r.lower[k] = kd_round_float(lower[k], true);
    r.upper[k] = kd_round_float(upper[k], false);
  }
  return r;
}

struct Split {
  int axis = -1;
  float pos = 0.0f;
  double cost = 0.0;
  std::size_t n_below = 0, n_above = 0;  // primitives each side lists
};

// Binned subtrees of at least this many references may be queued to
// another thread.
constexpr std::size_t kParallelMin = 1024;
// The exact build hands a subtree of at least this many references to a
// spare thread, which allocates its own side per primitive.
constexpr std::size_t kExactParallelMin = 4096;

// Candidate planes per axis of a binned split: the boundaries of this many
// equal bins over the node box.
constexpr int kBins = 64;

// Primitive sides during one split (bit 0: below, bit 1: above).
enum Side : std::uint8_t { kBelow = 1, kAbove = 2, kBoth = 3 };

// Where a node stands on its path from the root: its depth, the splits
// above it that cost more than a leaf (is_leaf), and the references its
// subtree may list (its share of kKdReferenceBudget).
struct KdPath {
  int depth = 0;
  int costly_splits = 0;
  double budget = 0.0;
};

// A subtree left to a worker thread: its root's placeholder in the tree,
// box and references, and its path.
struct KdTask {
  KdBuildNode* node;
  glm::dvec3 lower, upper;
  std::vector<Ref> refs;
  KdPath path;
};

// The subtrees the binned levels leave to workers (KdTask), handed out
// largest first while the binned levels are still adding to them.
class KdTaskQueue {
 public:
  void push(KdTask task) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      tasks_.push_back(std::move(task));
    }
    ready_.notify_one();
  }

  // No more tasks will come.
  void close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
  }

  // The largest waiting task; false once closed and empty.
  bool pop(KdTask* task) {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait(lock, [&] { return !tasks_.empty() || closed_; });
    if (tasks_.empty()) return false;
    auto largest = std::max_element(tasks_.begin(), tasks_.end(), [](const KdTask& a, const KdTask& b) {
      return a.refs.size() < b.refs.size();
    });
    *task = std::move(*largest);
    tasks_.erase(largest);
    return true;
  }

 private:
  std::mutex mutex_;
  std::condition_variable ready_;
  std::vector<KdTask> tasks_;
  bool closed_ = false;
};

// The split cost and the leaf cost of the SAH (KdTreeConfig), shared by the
// binned and the exact split.
class KdCost {
 public:
  explicit KdCost(const KdTreeConfig& config)
      : config_(config), shift_(std::has_single_bit(config.batch) ? std::countr_zero(config.batch) : -1) {}

  double leaf(std::size_t n) const { return config_.intersection_cost * tests(n); }

  // Intersection tests a leaf of n primitives costs: one per batch of
  // config.batch (the kernel tests up to 8 at once in float8 lanes), a
  // shift for the batches of 1, 2, 4 and 8 (the sweeps evaluate it twice
  // per candidate plane).
  double tests(std::size_t n) const {
    std::size_t runs = n + config_.batch - 1;
    return static_cast<double>(shift_ >= 0 ? runs >> shift_ : runs / config_.batch);
  }

  const KdTreeConfig& config() const { return config_; }

 private:
  const KdTreeConfig& config_;
  int shift_;  // log2(batch) when batch is a power of two, else -1
};

// The SAH cost of the splits of one node's box [lower, upper].
class KdSplitCost {
 public:
  KdSplitCost(const KdCost& cost, const glm::dvec3& lower, const glm::dvec3& upper)
      : cost_(cost), lower_(lower), upper_(upper) {
    glm::dvec3 e = upper - lower;
    double area = 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
    valid_ = area > 0.0;
    double scale = cost.config().intersection_cost / area;
    for (int k = 0; k < 3; ++k) {
      int a = (k + 1) % 3, b = (k + 2) % 3;
      cross_[k] = 2.0 * e[a] * e[b] * scale;
      perimeter_[k] = 2.0 * (e[a] + e[b]) * scale;
    }
  }

  // False for a node without area (no split is cheaper than its leaf).
  bool valid() const { return valid_; }

  // Split at p on axis k with n_below and n_above primitives listed each
  // side.
  double operator()(int k, double p, std::size_t n_below, std::size_t n_above) const {
    const KdTreeConfig& c = cost_.config();
    double below = cross_[k] + (p - lower_[k]) * perimeter_[k];
    double above = cross_[k] + (upper_[k] - p) * perimeter_[k];
    double cost = c.traversal_cost + below * cost_.tests(n_below) + above * cost_.tests(n_above);
    if (n_below == 0 || n_above == 0) cost *= 1.0 - c.empty_bonus;
    return cost;
  }

 private:
  const KdCost& cost_;
  glm::dvec3 lower_, upper_;
  std::array<double, 3> cross_, perimeter_;  // scaled by ci / area
  bool valid_;
};

// Both builds list a primitive below a plane p on axis k when its bounds
// start before p, above when they end after it, on both sides when they are
// flat on p. Bounds ending exactly at p are below only (they are rounded
// outwards, so the primitive does not reach beyond p), starting at p above
// only. Widening here would list a primitive ending at p as a sliver on the
// far side, which the SAH cuts around again and again.
std::uint8_t side_of(float lower, float upper, float p) {
  if (lower == p && upper == p) return kBoth;
  return static_cast<std::uint8_t>((lower < p ? kBelow : 0) | (upper > p ? kAbove : 0));
}

// A large node splits even when its best split costs more than its leaf,
// at most kCostlySplits times on a path (after pbrt's "bad refines",
// Pharr et al., pbrt-v3 section 4.4). Large: more than one run of eight
// lanes, and more than four runs or an eighth of the scene's primitives.
// The SAH alone can leave a small scene whose walls span every plane (the
// Cornell box's 36 triangles) in one leaf, every ray testing all of it;
// three forced splits per path fix that. Forcing splits of every node
// above one run would instead lengthen the build of large scenes
// (docs/benchmarks.md, levers).
constexpr std::size_t kRun = 8;
constexpr std::size_t kLargeLeaf = 4 * kRun;
constexpr int kCostlySplits = 3;

bool is_large(std::size_t n, std::size_t scene) { return n > kRun && (n > kLargeLeaf || 8 * n > scene); }

// Whether a node of n references (of `scene` stored primitives) at `path`
// is a leaf: no split, a split beyond the subtree's budget, or one that
// costs more than the leaf (unless the node is large, the split leaves
// fewer references on one side and the path has taken fewer than
// kCostlySplits such splits).
bool is_leaf(const Split& split, double leaf_cost, std::size_t n, std::size_t scene, const KdPath& path) {
  if (split.axis < 0 || static_cast<double>(split.n_below + split.n_above) > path.budget) return true;
  if (split.cost < leaf_cost) return false;
  return !is_large(n, scene) || std::min(split.n_below, split.n_above) >= n || path.costly_splits >= kCostlySplits;
}

// The children's paths: their shares of the budget from the split's counts
// (upper bounds of what the clipping keeps).
std::array<KdPath, 2> child_paths(const KdPath& path, const Split& split, double leaf_cost) {
  const double both = static_cast<double>(split.n_below + split.n_above);
  const int costly = path.costly_splits + (split.cost >= leaf_cost ? 1 : 0);
  return {KdPath{path.depth + 1, costly, path.budget * static_cast<double>(split.n_below) / both},
          KdPath{path.depth + 1, costly, path.budget * static_cast<double>(split.n_above) / both}};
}

// The leaf of `node` listing `prims` (sorted), with the union of their
// clipped bounds.
void make_leaf(KdBuildNode& node, std::vector<std::uint32_t> prims, const KdBox& content) {
  node.prims = std::move(prims);
  std::sort(node.prims.begin(), node.prims.end());
  node.has_content = true;
  node.content = content;
}

// The exact build of Wald & Havran 2006, O(N log N): the events of a
// subtree's references sorted once per axis, one sweep per axis over every
// event position of a node, the children's lists filtered from the
// parent's (keeping them sorted) and merged with the re-sorted events of
// the straddling primitives clipped to each child. Subtrees of at least
// kExactParallelMin references go to spare host threads.
class ExactBuilder {
 public:
  ExactBuilder(const KdPrimitives& prims, const KdTreeConfig& config, int max_depth, unsigned threads)
      : prims_(prims), cost_(config), max_depth_(max_depth), threads_(static_cast<int>(threads) - 1) {}

  void build(KdBuildNode& node, const glm::dvec3& lower, const glm::dvec3& upper, const std::vector<Ref>& refs,
             const KdPath& path) {
    Events events;
    for (auto& list : events) list.reserve(2 * refs.size());
    for (const Ref& r : refs) add_events(events, r);
    if (refs.size() >= kExactParallelMin && threads_.try_take()) {
      run_jobs(2, [&](unsigned job) {
        if (job == 1) {
          std::sort(events[1].begin(), events[1].end());
          return;
        }
        std::sort(events[0].begin(), events[0].end());
        std::sort(events[2].begin(), events[2].end());
      });
      threads_.give_back();
    } else {
      for (auto& list : events) std::sort(list.begin(), list.end());
    }
    if (side_.empty()) side_.assign(prims_.size(), 0);
    build(node, lower, upper, std::move(events), path, side_);
  }

 private:
  using Events = std::array<std::vector<Event>, 3>;

  static void add_events(Events& events, const Ref& r) {
    for (int k = 0; k < 3; ++k) {
      if (r.lower[k] == r.upper[k]) {
        events[k].push_back({r.lower[k], r.prim, kPlanar});
      } else {
        events[k].push_back({r.lower[k], r.prim, kStart});
        events[k].push_back({r.upper[k], r.prim, kEnd});
      }
    }
  }

  // `side`: all zero, one entry per primitive, this thread's.
  void build(KdBuildNode& node, const glm::dvec3& lower, const glm::dvec3& upper, Events events,
             const KdPath& path, std::vector<std::uint8_t>& side) {
    std::size_t n = 0;
    for (const Event& e : events[0]) n += e.type != kEnd;
    Split split;
    if (path.depth < max_depth_ && n > 0) split = find_split(lower, upper, events, n);
    const double leaf_cost = cost_.leaf(n);
    if (is_leaf(split, leaf_cost, n, prims_.size(), path)) {
      std::vector<std::uint32_t> prims;
      prims.reserve(n);
      for (const Event& e : events[0])
        if (e.type != kEnd) prims.push_back(e.prim);
      KdBox content = KdBox::empty();
      for (int a = 0; a < 3 && n > 0; ++a) {
        content.lower[a] = events[a].front().pos;
        content.upper[a] = events[a].back().pos;
      }
      make_leaf(node, std::move(prims), content);
      return;
    }
    const int k = split.axis;
    const float p = split.pos;
    node.axis = k;
    node.split = p;
    // Sides, as the sweep counted them (side_of).
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
      below[a].reserve(2 * split.n_below);
      above[a].reserve(2 * split.n_above);
      for (const Event& e : events[a]) {
        if (side[e.prim] == kBelow) below[a].push_back(e);
        else if (side[e.prim] == kAbove) above[a].push_back(e);
      }
    }
    std::array<bool, 2> reaches;
    std::array<glm::dvec3, 2> cl, cu;
    for (const Event& e : events[k]) {
      if (e.type == kEnd) continue;
      if (side[e.prim] == kBoth) {
        prims_.clip_split(e.prim, lower, upper, k, p, &reaches, &cl, &cu);
        if (reaches[0]) add_events(below_new, make_ref(e.prim, cl[0], cu[0]));
        if (reaches[1]) add_events(above_new, make_ref(e.prim, cl[1], cu[1]));
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
    // Not a structured binding: the lambda below uses both, and clang before
    // 16 cannot capture one (the fuzz targets build this file with clang).
    const std::array<KdPath, 2> paths = child_paths(path, split, leaf_cost);
    const KdPath& below_path = paths[0];
    const KdPath& above_path = paths[1];
    node.below = std::make_unique<KdBuildNode>();
    node.above = std::make_unique<KdBuildNode>();
    if (n >= kExactParallelMin && threads_.try_take()) {
      run_jobs(2, [&](unsigned job) {
        if (job == 0) {
          build(*node.above, above_lower, upper, std::move(above), above_path, side);
          return;
        }
        std::vector<std::uint8_t> own(prims_.size(), 0);
        build(*node.below, lower, below_upper, std::move(below), below_path, own);
      });
      threads_.give_back();
    } else {
      build(*node.below, lower, below_upper, std::move(below), below_path, side);
      build(*node.above, above_lower, upper, std::move(above), above_path, side);
    }
  }

  static void merge_in(std::vector<Event>& into, std::vector<Event>& added) {
    if (added.empty()) return;
    std::sort(added.begin(), added.end());
    std::size_t middle = into.size();
    into.insert(into.end(), added.begin(), added.end());
    std::inplace_merge(into.begin(), into.begin() + static_cast<std::ptrdiff_t>(middle), into.end());
  }

  // The sweep over each axis's sorted events (Wald & Havran 2006,
  // algorithm 4): N_L, N_P, N_R at every event position strictly inside
  // the node. Planar primitives at the plane count on both sides (the
  // build lists them on both). Axis -1 when no split beats a leaf.
  Split find_split(const glm::dvec3& lower, const glm::dvec3& upper, const Events& events, std::size_t n) const {
    Split best;
    best.cost = std::numeric_limits<double>::infinity();
    KdSplitCost split_cost(cost_, lower, upper);
    if (!split_cost.valid()) return best;
    for (int k = 0; k < 3; ++k) {
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
          double cost = split_cost(k, p, n_below, n_above);
          if (cost < best.cost) best = {k, p, cost, n_below, n_above};
        }
        left += starting + planar;
      }
    }
    return best;
  }

  const KdPrimitives& prims_;
  KdCost cost_;
  int max_depth_;
  KdThreads threads_;
  std::vector<std::uint8_t> side_;  // this thread's sides, all zero between splits
};

// The binned build: the same costs, sides and perfect splits as the exact
// one, the planes at the boundaries of up to kBins equal bins per axis
// (min-max binning: a reference counts in the bin of its lower and of its
// upper bound), linear in a node's references with no sorting. Nodes of at
// most config.exact_below references go to the exact build.
class BinnedBuilder {
 public:
  BinnedBuilder(const KdPrimitives& prims, const KdTreeConfig& config, int max_depth)
      : prims_(prims), config_(config), cost_(config), max_depth_(max_depth), exact_(prims, config, max_depth, 1) {}

  // Builds the subtree of `node`; with `deferred`, nodes of at most
  // `defer_at` references below this one are left there instead (their
  // subtrees built later, on other threads).
  void build(KdBuildNode& node, const glm::dvec3& lower, const glm::dvec3& upper, std::vector<Ref> refs,
             const KdPath& path, std::size_t defer_at = 0, KdTaskQueue* deferred = nullptr) {
    const std::size_t n = refs.size();
    if (n <= config_.exact_below) {
      exact_.build(node, lower, upper, refs, path);
      return;
    }
    Split split;
    if (path.depth < max_depth_) split = find_split(lower, upper, refs);
    const double leaf_cost = cost_.leaf(n);
    if (is_leaf(split, leaf_cost, n, prims_.size(), path)) {
      std::vector<std::uint32_t> prims;
      prims.reserve(n);
      KdBox content = KdBox::empty();
      for (const Ref& r : refs) {
        prims.push_back(r.prim);
        content.grow({{r.lower[0], r.lower[1], r.lower[2]}, {r.upper[0], r.upper[1], r.upper[2]}});
      }
      make_leaf(node, std::move(prims), content);
      return;
    }
    const int k = split.axis;
    const float p = split.pos;
    node.axis = k;
    node.split = p;
    glm::dvec3 below_upper = upper, above_lower = lower;
    below_upper[k] = p;
    above_lower[k] = p;
    std::vector<Ref> below, above;
    below.reserve(split.n_below);
    above.reserve(split.n_above);
    std::array<bool, 2> reaches;
    std::array<glm::dvec3, 2> cl, cu;
    for (const Ref& r : refs) {
      std::uint8_t side = side_of(r.lower[k], r.upper[k], p);
      if (side == kBelow) {
        below.push_back(r);
      } else if (side == kAbove) {
        above.push_back(r);
      } else {
        prims_.clip_split(r.prim, lower, upper, k, p, &reaches, &cl, &cu);
        if (reaches[0]) below.push_back(make_ref(r.prim, cl[0], cu[0]));
        if (reaches[1]) above.push_back(make_ref(r.prim, cl[1], cu[1]));
      }
    }
    refs = {};
    const auto [below_path, above_path] = child_paths(path, split, leaf_cost);
    node.below = std::make_unique<KdBuildNode>();
    node.above = std::make_unique<KdBuildNode>();
    child(*node.below, lower, below_upper, std::move(below), below_path, defer_at, deferred);
    child(*node.above, above_lower, upper, std::move(above), above_path, defer_at, deferred);
  }

 private:
  void child(KdBuildNode& node, const glm::dvec3& lower, const glm::dvec3& upper, std::vector<Ref> refs,
             const KdPath& path, std::size_t defer_at, KdTaskQueue* deferred) {
    if (deferred && refs.size() <= defer_at)
      deferred->push({&node, lower, upper, std::move(refs), path});
    else
      build(node, lower, upper, std::move(refs), path, defer_at, deferred);
  }

  // Planes at the bin boundaries strictly inside the node (a bin per two
  // references, from 8 to kBins): N_below counts the references whose
  // lower bound lies in a bin below the plane, N_above those whose upper
  // bound lies in a bin above it (both upper bounds of what the split
  // lists). Axis -1 when no plane beats a leaf.
  Split find_split(const glm::dvec3& lower, const glm::dvec3& upper, const std::vector<Ref>& refs) const {
    const std::size_t n = refs.size();
    Split best;
    best.cost = std::numeric_limits<double>::infinity();
    KdSplitCost split_cost(cost_, lower, upper);
    if (!split_cost.valid()) return best;
    const int bins = static_cast<int>(std::clamp<std::size_t>(n / 2, 8, kBins));
    std::array<std::array<std::uint32_t, kBins>, 3> starts, ends;
    glm::dvec3 extent = upper - lower;
    Float4 origin{}, to_bin{};
    for (int k = 0; k < 3; ++k) {
      std::fill_n(starts[k].begin(), bins, 0u);
      std::fill_n(ends[k].begin(), bins, 0u);
      origin[k] = static_cast<float>(lower[k]);
      to_bin[k] = extent[k] > 0.0 ? static_cast<float>(bins / extent[k]) : 0.0f;
    }
    const Float4 zero{}, last = Float4{} + static_cast<float>(bins - 1);
    // The bins of a bound's three coordinates at once (lane 3 unused).
    auto bin = [&](const float* xyz) {
      Float4 b = (load4(xyz) - origin) * to_bin;
      b = b > zero ? b : zero;
      b = b < last ? b : last;
      return __builtin_convertvector(b, Int4);
    };
    for (const Ref& r : refs) {
      Int4 s = bin(r.lower.data()), e = bin(r.upper.data());
      for (int k = 0; k < 3; ++k) {
        ++starts[k][s[k]];
        ++ends[k][e[k]];
      }
    }
    for (int k = 0; k < 3; ++k) {
      if (!(extent[k] > 0.0)) continue;
      std::size_t left = 0, right = n;
      const double step = extent[k] / bins;
      for (int j = 1; j < bins; ++j) {
        left += starts[k][j - 1];
        right -= ends[k][j - 1];
        float p = static_cast<float>(lower[k] + step * j);
        if (!(p > lower[k] && p < upper[k])) continue;
        double cost = split_cost(k, p, left, right);
        if (cost < best.cost) best = {k, p, cost, left, right};
      }
    }
    return best;
  }

  const KdPrimitives& prims_;
  const KdTreeConfig& config_;
  KdCost cost_;
  int max_depth_;
  ExactBuilder exact_;
};

// Builds the tree from the root's references. A root of at most
// config.exact_below references: the exact build, on its own threads.
// Otherwise this thread splits the binned levels down to nodes of at most
// 1/16 of the references (at least kParallelMin) and queues those
// subtrees, which `threads` - 1 workers build meanwhile; then it builds
// queued subtrees too.
std::unique_ptr<KdBuildNode> build_tree(const KdPrimitives& prims, const KdTreeConfig& config, int depth,
                                        unsigned threads, std::vector<Ref> refs) {
  auto root = std::make_unique<KdBuildNode>();
  const std::size_t n = refs.size();
  const KdPath path{0, 0, kKdReferenceBudget * static_cast<double>(n)};
  if (n <= config.exact_below) {
    ExactBuilder(prims, config, depth, threads).build(*root, prims.lower, prims.upper, refs, path);
    return root;
  }
  BinnedBuilder top(prims, config, depth);
  if (threads < 2 || n < 2 * kParallelMin) {
    top.build(*root, prims.lower, prims.upper, std::move(refs), path);
    return root;
  }
  KdTaskQueue queue;
  auto work = [&] {
    BinnedBuilder builder(prims, config, depth);
    for (KdTask t; queue.pop(&t);) builder.build(*t.node, t.lower, t.upper, std::move(t.refs), t.path);
  };
  std::vector<std::jthread> workers;
  for (unsigned t = 1; t < threads; ++t) workers.emplace_back(work);
  try {
    top.build(*root, prims.lower, prims.upper, std::move(refs), path, std::max(kParallelMin, n / 16), &queue);
  } catch (...) {
    queue.close();
    throw;
  }
  queue.close();
  work();
  return root;
}

}  // namespace

int kdtree_depth(const KdTreeConfig& config, std::size_t primitives) {
  if (config.depth > 0) return config.depth;
  double n = static_cast<double>(std::max<std::size_t>(primitives, 1));
  return std::clamp(static_cast<int>(std::lround(8.0 + 1.3 * std::log2(n))), 1, kKdMaxDepth);
}

KdTree build_kdtree(const Geometry& geometry, const KdTreeConfig& config) {
  KdPrimitives prims = kd_primitives(geometry, "kdtree", config.max_alloc_bytes);
  int depth = kdtree_depth(config, prims.size());
  unsigned threads = config.thread_count ? config.thread_count : std::max(1u, std::thread::hardware_concurrency());
  // The root's references: the primitives' own bounds (the root box holds
  // them all).
  std::vector<Ref> refs(prims.size());
  for (std::uint32_t i = 0; i < prims.size(); ++i) {
    glm::dvec3 lo, hi;
    prims.bounds(i, &lo, &hi);
    refs[i] = make_ref(i, lo, hi);
  }
  auto root = build_tree(prims, config, depth, threads, std::move(refs));
  return flatten_kd_tree(prims, *root, "kdtree", "depth=" + std::to_string(depth), config.max_alloc_bytes, threads);
}

namespace {

// The build options, the one declaration of their defaults (KdTreeConfig's)
// and ranges; with the single-ray kernel's occlusion queries (`kdtree`)
// also occluder_run, which the packet kernel does not have.
std::vector<OptionSpec> kdtree_options(bool occluder_runs) {
  static const KdTreeConfig d;
  std::vector<OptionSpec> options = {{"depth", OptionType::integer, std::int64_t{d.depth}, 0, kKdMaxDepth, false,
           "deepest leaf in splits, at most the traversal stack; 0: round(8 + 1.3 log2 N)"},
          {"ct", OptionType::real, d.traversal_cost, 0, 1e6, true,
           "SAH cost of one node step: higher makes shallower trees with larger leaves"},
          {"ci", OptionType::real, d.intersection_cost, 0, 1e6, true,
           "SAH cost of one primitive test: higher makes deeper trees with smaller leaves"},
          {"empty", OptionType::real, d.empty_bonus, 0, 0.99, false,
           "empty-space bonus: a split with one empty side costs (1 - empty) times its SAH cost"},
          {"batch", OptionType::integer, std::int64_t{d.batch}, 1, 8, false,
           "primitives per intersection test in the SAH (1: classic; 8: the kernel's float8 batch, larger leaves)"},
          {"exact", OptionType::integer, static_cast<std::int64_t>(d.exact_below), 0, 1073741824.0, false,
           "nodes of at most this many references split by the exact sweep over sorted events, larger ones at 64 bin "
           "boundaries per axis"}};
  if (occluder_runs) options.push_back(occluder_run_option());
  return options;
}

std::unique_ptr<Accel> make_kdtree_from(const StructureSpec& spec, KdTraversal traversal, const Device& device,
                                        const Geometry& geometry, const AccelConfig& config) {
  const AccelOptions& o = config.options;
  KdTreeConfig kd;
  kd.depth = static_cast<int>(o.integer("depth"));
  kd.traversal_cost = o.real("ct");
  kd.intersection_cost = o.real("ci");
  kd.empty_bonus = o.real("empty");
  kd.batch = static_cast<unsigned>(o.integer("batch"));
  kd.exact_below = static_cast<std::size_t>(o.integer("exact"));
  if (o.has("occluder_run")) kd.occluder_run = static_cast<std::uint32_t>(o.integer("occluder_run"));
  return make_kdtree(device, geometry, kd, config, spec.name, traversal);
}

}  // namespace

const StructureSpec& kdtree_structure() {
  static const StructureSpec spec{
      "kdtree",
      "SAH kd-tree: O(N log N) sorted-event build, perfect splits, [min,max] interval traversal; packets of 8 rays "
      "for coherent calls on CPU devices",
      kdtree_options(true)};
  return spec;
}

const StructureSpec& kdtree_packet_structure() {
  static const StructureSpec spec{"kdtree-packet", "the kdtree, always traced in packets of 8 rays (for measuring)",
                                  kdtree_options(false)};
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
      accel_config, traversal, config.occluder_run);
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
