#include "rtcl/accel/bvh_ploc.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <thread>
#include <vector>

#include "rtcl/accel/bvh_sah.hpp"
#include "rtcl/error.hpp"
#include "rtcl/layouts.hpp"
#include "rtcl/parallel.hpp"

namespace rtcl {

namespace {

constexpr std::uint32_t kNone = 0xffffffffu;

// Spreads the low 10 bits of x to every third bit (Morton interleave).
std::uint32_t spread_bits(std::uint32_t x) {
  x &= 0x3ffu;
  x = (x | (x << 16)) & 0x030000ffu;
  x = (x | (x << 8)) & 0x0300f00fu;
  x = (x | (x << 4)) & 0x030c30c3u;
  x = (x | (x << 2)) & 0x09249249u;
  return x;
}

// Input positions sorted by the 30-bit Morton code of their box centres
// within the centres' bounds; equal codes keep input order (LSD radix sort).
std::vector<std::uint32_t> morton_order(std::span<const Aabb> bounds) {
  const std::size_t n = bounds.size();
  Aabb centres;
  for (const Aabb& b : bounds) centres.grow(0.5f * b.lower + 0.5f * b.upper);
  glm::vec3 extent = centres.extent();
  glm::vec3 scale(0.0f);
  for (int a = 0; a < 3; ++a)
    if (extent[a] > 0.0f && std::isfinite(extent[a])) scale[a] = 1023.0f / extent[a];
  std::vector<std::uint32_t> code(n), order(n), code_tmp(n), order_tmp(n);
  for (std::size_t i = 0; i < n; ++i) {
    glm::vec3 c = 0.5f * bounds[i].lower + 0.5f * bounds[i].upper;
    std::uint32_t q[3];
    for (int a = 0; a < 3; ++a) q[a] = std::min(1023u, static_cast<std::uint32_t>((c[a] - centres.lower[a]) * scale[a]));
    code[i] = (spread_bits(q[0]) << 2) | (spread_bits(q[1]) << 1) | spread_bits(q[2]);
    order[i] = static_cast<std::uint32_t>(i);
  }
  for (int shift = 0; shift < 30; shift += 10) {
    std::uint32_t histogram[1025] = {};
    for (std::size_t i = 0; i < n; ++i) ++histogram[((code[i] >> shift) & 1023u) + 1];
    for (int k = 0; k < 1024; ++k) histogram[k + 1] += histogram[k];
    for (std::size_t i = 0; i < n; ++i) {
      std::uint32_t slot = histogram[(code[i] >> shift) & 1023u]++;
      code_tmp[slot] = code[i];
      order_tmp[slot] = order[i];
    }
    code.swap(code_tmp);
    order.swap(order_tmp);
  }
  return order;
}

// Cluster boxes, SoA so that the distance loop over a window vectorises.
struct Clusters {
  std::vector<float> lx, ly, lz, hx, hy, hz;
  std::vector<std::uint32_t> node;

  std::size_t size() const { return node.size(); }
  void resize(std::size_t n) {
    for (auto* v : {&lx, &ly, &lz, &hx, &hy, &hz}) v->resize(n);
    node.resize(n);
  }
  void set(std::size_t i, const Aabb& b, std::uint32_t node_index) {
    lx[i] = b.lower.x, ly[i] = b.lower.y, lz[i] = b.lower.z;
    hx[i] = b.upper.x, hy[i] = b.upper.y, hz[i] = b.upper.z;
    node[i] = node_index;
  }
  Aabb box(std::size_t i) const { return {{lx[i], ly[i], lz[i]}, {hx[i], hy[i], hz[i]}}; }
};

// Binary tree as clustering makes it: nodes [0, n) are the primitives (node p
// = input position p), merges are appended, so children precede parents.
struct MergeNode {
  Aabb bounds;
  std::uint32_t child[2] = {kNone, kNone};
};

// Nearest neighbour of every cluster in [begin, end) within `radius` places.
// Ties are broken by a total order on unordered pairs (distance, index gap,
// odd lower index, lower index), so the globally closest pair is always
// mutual, and equal boxes pair up as (0,1), (2,3), ... rather than forming
// one chain.
void nearest_neighbours(const Clusters& c, std::uint32_t radius, std::size_t begin, std::size_t end,
                        std::vector<std::uint32_t>& nn) {
  const std::size_t m = c.size();
  std::vector<float> d(2 * radius + 1);
  for (std::size_t i = begin; i < end; ++i) {
    std::size_t lo = i >= radius ? i - radius : 0, hi = std::min(m, i + radius + 1);
    const float ilx = c.lx[i], ily = c.ly[i], ilz = c.lz[i], ihx = c.hx[i], ihy = c.hy[i], ihz = c.hz[i];
    for (std::size_t j = lo; j < hi; ++j) {
      float x = std::max(ihx, c.hx[j]) - std::min(ilx, c.lx[j]);
      float y = std::max(ihy, c.hy[j]) - std::min(ily, c.ly[j]);
      float z = std::max(ihz, c.hz[j]) - std::min(ilz, c.lz[j]);
      d[j - lo] = x * y + y * z + z * x;
    }
    std::size_t best = kNone;
    float best_d = std::numeric_limits<float>::infinity();
    std::size_t best_gap = 0, best_min = 0;
    for (std::size_t j = lo; j < hi; ++j) {
      if (j == i) continue;
      float dj = d[j - lo];
      std::size_t gap = j > i ? j - i : i - j, low = std::min(i, j);
      bool better = best == kNone || dj < best_d ||
                    (dj == best_d && (gap < best_gap || (gap == best_gap && ((low & 1) < (best_min & 1) ||
                                                                             ((low & 1) == (best_min & 1) &&
                                                                              low < best_min)))));
      if (better) best = j, best_d = dj, best_gap = gap, best_min = low;
    }
    nn[i] = static_cast<std::uint32_t>(best);
  }
}

class PlocBuilder {
 public:
  PlocBuilder(std::span<const Aabb> bounds, std::span<const std::uint32_t> ids, const PlocConfig& config)
      : bounds_(bounds), ids_(ids), config_(config) {
    threads_ = config.thread_count ? config.thread_count : std::max(1u, std::thread::hardware_concurrency());
  }

  BuildTree run() {
    if (bounds_.empty()) return {};
    std::uint32_t root = cluster();
    form_leaves();
    BuildTree tree;
    emit(root, tree);
    return tree;
  }

 private:
  // Agglomerates all primitives; returns the root's index in merge_.
  std::uint32_t cluster() {
    const std::size_t n = bounds_.size();
    merge_.resize(n);
    merge_.reserve(2 * n - 1);
    for (std::size_t p = 0; p < n; ++p) merge_[p].bounds = bounds_[p];
    std::vector<std::uint32_t> order = morton_order(bounds_);
    Clusters c, next;
    c.resize(n);
    for (std::size_t i = 0; i < n; ++i) c.set(i, bounds_[order[i]], order[i]);
    std::vector<std::uint32_t> nn(n);
    while (c.size() > 1) {
      const std::size_t m = c.size();
      unsigned workers = m >= config_.parallel_min_clusters ? threads_ : 1;
      for_each_part(m, workers, [&](unsigned, std::size_t begin, std::size_t end) {
        nearest_neighbours(c, config_.search_radius, begin, end, nn);
      });
      // Progress guarantee: inputs whose boxes all overlap alike (a fan of
      // triangles around one shared vertex) form nearest-neighbour chains
      // with a single mutual pair each, so clustering would take O(n)
      // rounds; a round that would merge under 1/64 of the clusters pairs
      // Morton neighbours instead, which bounds the rounds by O(log n)
      // (ordinary scenes merge a fifth or more of their clusters a round
      // and never take this branch).
      std::size_t mutual = 0;
      for (std::size_t i = 0; i < m; ++i) mutual += nn[nn[i]] == i && nn[i] > i;
      if (m >= 64 && mutual < m / 64)
        for (std::size_t i = 0; i < m; ++i) nn[i] = static_cast<std::uint32_t>((i ^ 1u) < m ? i ^ 1u : i - 1);  // an odd last one waits
      next.resize(0);
      next.resize(m);
      std::size_t kept = 0;
      for (std::size_t i = 0; i < m; ++i) {
        std::uint32_t j = nn[i];
        if (nn[j] == i) {
          if (j < i) continue;  // merged into cluster j
          MergeNode parent;
          parent.bounds = merge(c.box(i), c.box(j));
          parent.child[0] = c.node[i];
          parent.child[1] = c.node[j];
          merge_.push_back(parent);
          next.set(kept++, parent.bounds, static_cast<std::uint32_t>(merge_.size() - 1));
        } else {
          next.set(kept++, c.box(i), c.node[i]);
        }
      }
      next.resize(kept);
      std::swap(c, next);
    }
    return c.node[0];
  }

  // Bottom-up SAH decision (children precede parents in merge_), with
  // cost = area * (node_cost per node + 1 per block test):
  // - a subtree of up to max_leaf primitives becomes one leaf when that is
  //   not costlier than keeping it;
  // - a subtree of up to 2 * max_leaf primitives may instead be re-split
  //   into two leaves by a SAH sweep over its centroids: clustering fixes
  //   the topology without regard to block size, and re-splitting such
  //   small subtrees fills blocks (9 + 7 primitives: 3 blocks, 8 + 8: 2).
  void form_leaves() {
    const std::size_t total = merge_.size();
    count_.assign(total, 1);
    leaf_.assign(total, 1);
    repack_.assign(total, kNone);
    std::vector<float> cost(total);
    std::vector<std::uint32_t> positions;
    for (std::size_t k = 0; k < total; ++k) {
      const MergeNode& m = merge_[k];
      float area = m.bounds.area();
      if (m.child[0] == kNone) {
        cost[k] = area;
        continue;
      }
      count_[k] = count_[m.child[0]] + count_[m.child[1]];
      float split = config_.node_cost * area + cost[m.child[0]] + cost[m.child[1]];
      leaf_[k] = count_[k] <= config_.max_leaf_size && area <= split;
      cost[k] = leaf_[k] ? area : split;
      if (!leaf_[k] && count_[k] <= 2 * config_.max_leaf_size) {
        positions.clear();
        gather(static_cast<std::uint32_t>(k), positions);
        TwoLeaves two = best_two_leaves(positions);
        float repacked = config_.node_cost * area + two.cost;
        if (repacked < cost[k]) {
          cost[k] = repacked;
          repack_[k] = static_cast<std::uint32_t>(repacks_.size());
          repacks_.push_back(two);
        }
      }
    }
  }

  struct TwoLeaves {
    std::array<std::uint32_t, 2 * RTCL_BLOCK_WIDTH> positions{};  // left leaf, then right leaf
    std::uint32_t count = 0, split = 0;
    float cost = std::numeric_limits<float>::infinity();  // area(left) + area(right)
  };

  // The cheapest split of `positions` (at most 2 * max_leaf) into two leaves
  // of at most max_leaf each, over the centroid order along each axis.
  TwoLeaves best_two_leaves(const std::vector<std::uint32_t>& positions) const {
    TwoLeaves best;
    const auto n = static_cast<std::uint32_t>(positions.size());
    best.count = n;
    std::array<std::uint32_t, 2 * RTCL_BLOCK_WIDTH> order{};
    std::array<float, 2 * RTCL_BLOCK_WIDTH + 1> right_area{};
    for (int axis = 0; axis < 3; ++axis) {
      std::copy(positions.begin(), positions.end(), order.begin());
      auto centre = [&](std::uint32_t p) { return bounds_[p].lower[axis] + bounds_[p].upper[axis]; };
      std::sort(order.begin(), order.begin() + n,
                [&](std::uint32_t a, std::uint32_t b) { return centre(a) < centre(b); });
      Aabb acc;
      for (std::uint32_t i = n; i-- > 0;) {
        acc.grow(bounds_[order[i]]);
        right_area[i] = acc.area();
      }
      acc = Aabb();
      std::uint32_t first = n > config_.max_leaf_size ? n - config_.max_leaf_size : 1;
      for (std::uint32_t i = 1; i < n; ++i) {
        acc.grow(bounds_[order[i - 1]]);
        if (i < first || i > config_.max_leaf_size) continue;
        float c = acc.area() + right_area[i];
        if (c < best.cost) {
          best.cost = c;
          best.split = i;
          best.positions = order;
        }
      }
    }
    return best;
  }

  // Primitive positions below merge node k, left to right.
  void gather(std::uint32_t k, std::vector<std::uint32_t>& out) const {
    std::vector<std::uint32_t> todo{k};
    while (!todo.empty()) {
      std::uint32_t x = todo.back();
      todo.pop_back();
      if (merge_[x].child[0] == kNone) {
        out.push_back(x);
      } else {
        todo.push_back(merge_[x].child[1]);
        todo.push_back(merge_[x].child[0]);
      }
    }
  }

  // Writes the subtree of merge node `root` into tree, depth first.
  void emit(std::uint32_t root, BuildTree& tree) const {
    struct Todo {
      std::uint32_t merge_node, out_node, depth;
    };
    tree.nodes.emplace_back();
    std::vector<Todo> todo{{root, 0, 1}};
    std::vector<std::uint32_t> positions;
    while (!todo.empty()) {
      Todo t = todo.back();
      todo.pop_back();
      const MergeNode& m = merge_[t.merge_node];
      if (leaf_[t.merge_node]) {
        positions.clear();
        gather(t.merge_node, positions);
        BuildNode& leaf = tree.nodes[t.out_node];
        leaf.bounds = m.bounds;
        leaf.first = static_cast<std::uint32_t>(tree.prims.size());
        leaf.count = static_cast<std::uint32_t>(positions.size());
        for (std::uint32_t p : positions) tree.prims.push_back(ids_[p]);
        continue;
      }
      if (t.depth >= config_.max_depth) {
        splice_median_tree(t.merge_node, t.out_node, tree);
        continue;
      }
      if (repack_[t.merge_node] != kNone) {
        emit_two_leaves(repacks_[repack_[t.merge_node]], m.bounds, t.out_node, tree);
        continue;
      }
      auto first = static_cast<std::uint32_t>(tree.nodes.size());
      tree.nodes.emplace_back();
      tree.nodes.emplace_back();
      BuildNode& inner = tree.nodes[t.out_node];
      inner.bounds = m.bounds;
      inner.child[0] = first;
      inner.child[1] = first + 1;
      todo.push_back({m.child[1], first + 1, t.depth + 1});
      todo.push_back({m.child[0], first, t.depth + 1});
    }
  }

  void emit_two_leaves(const TwoLeaves& two, const Aabb& bounds, std::uint32_t out_node, BuildTree& tree) const {
    auto first = static_cast<std::uint32_t>(tree.nodes.size());
    tree.nodes[out_node].bounds = bounds;
    tree.nodes[out_node].child[0] = first;
    tree.nodes[out_node].child[1] = first + 1;
    for (int side = 0; side < 2; ++side) {
      std::uint32_t begin = side == 0 ? 0 : two.split, end = side == 0 ? two.split : two.count;
      BuildNode leaf;
      leaf.first = static_cast<std::uint32_t>(tree.prims.size());
      leaf.count = end - begin;
      for (std::uint32_t i = begin; i < end; ++i) {
        leaf.bounds.grow(bounds_[two.positions[i]]);
        tree.prims.push_back(ids_[two.positions[i]]);
      }
      tree.nodes.push_back(leaf);
    }
  }

  // Replaces the subtree below merge node k by a balanced one (object-median
  // splits), written at tree node out_node.
  void splice_median_tree(std::uint32_t k, std::uint32_t out_node, BuildTree& tree) const {
    std::vector<std::uint32_t> positions;
    gather(k, positions);
    std::vector<Aabb> sub_bounds;
    std::vector<std::uint32_t> sub_ids;
    for (std::uint32_t p : positions) {
      sub_bounds.push_back(bounds_[p]);
      sub_ids.push_back(ids_[p]);
    }
    SahConfig median;
    median.max_sah_depth = 0;
    median.max_leaf_size = config_.max_leaf_size;
    median.thread_count = 1;
    BuildTree sub = build_sah(sub_bounds, sub_ids, median);
    auto node_offset = static_cast<std::uint32_t>(tree.nodes.size() - 1);  // sub's node 0 goes to out_node
    auto prim_offset = static_cast<std::uint32_t>(tree.prims.size());
    for (std::size_t s = 0; s < sub.nodes.size(); ++s) {
      BuildNode node = sub.nodes[s];
      if (node.is_leaf()) {
        node.first += prim_offset;
      } else {
        node.child[0] += node_offset;
        node.child[1] += node_offset;
      }
      if (s == 0)
        tree.nodes[out_node] = node;
      else
        tree.nodes.push_back(node);
    }
    tree.prims.insert(tree.prims.end(), sub.prims.begin(), sub.prims.end());
  }

  std::span<const Aabb> bounds_;
  std::span<const std::uint32_t> ids_;
  const PlocConfig& config_;
  unsigned threads_ = 1;
  std::vector<MergeNode> merge_;
  std::vector<std::uint32_t> count_;
  std::vector<char> leaf_;
  std::vector<std::uint32_t> repack_;  // per merge node: index into repacks_, or kNone
  std::vector<TwoLeaves> repacks_;
};

}  // namespace

BuildTree build_ploc(std::span<const Aabb> bounds, std::span<const std::uint32_t> ids, const PlocConfig& config) {
  if (config.search_radius < 1 || config.search_radius > 1024)
    throw Error("PLOC builder: search_radius " + std::to_string(config.search_radius) + " is outside 1..1024");
  if (config.max_leaf_size < 1 || config.max_leaf_size > RTCL_BLOCK_WIDTH)
    throw Error("PLOC builder: max_leaf_size " + std::to_string(config.max_leaf_size) + " is outside 1..8");
  if (config.max_depth < 1) throw Error("PLOC builder: max_depth must be >= 1");
  if (!(config.node_cost >= 0.0f) || !std::isfinite(config.node_cost))
    throw Error("PLOC builder: node_cost must be finite and >= 0");
  check_builder_input(bounds, ids, "PLOC builder");
  return PlocBuilder(bounds, ids, config).run();
}

}  // namespace rtcl
