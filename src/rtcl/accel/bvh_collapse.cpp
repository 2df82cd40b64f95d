// plan_collapse (bvh_collapse.hpp).
#include "rtcl/accel/bvh_collapse.hpp"

#include <algorithm>
#include <limits>
#include <string>

#include "rtcl/error.hpp"
#include "rtcl/layouts.hpp"

namespace rtcl {

namespace {

constexpr int kWidth = RTCL_BLOCK_WIDTH;
constexpr float kInf = std::numeric_limits<float>::infinity();

// A finished subtree: its least cost for each budget 1..8 (at i - 1), its
// primitives (capped at kWidth + 1) and their kinds (bit 0 triangles, bit 1
// spheres, 3 also for a leaf that does not fit the geometry).
struct Subtree {
  std::array<float, kWidth> cost;
  std::uint8_t prims, kinds;
};

}  // namespace

void plan_subtree(const BuildTree& tree, const Geometry& geometry, std::uint32_t root, CollapsePlan& plan) {
  const std::size_t n = tree.nodes.size();
  auto fail = [&](const std::string& what) { throw Error("internal: BVH over " + geometry.source + ": " + what); };
  auto claim = [&](std::uint32_t m) {
    if (m >= n) fail("child " + std::to_string(m) + " does not exist");
    if (plan.seen_[m].exchange(1, std::memory_order_relaxed)) fail("node " + std::to_string(m) + " is reached twice");
  };
  claim(root);
  std::vector<Subtree> done;  // finished subtrees, a left one below its sibling
  std::vector<std::pair<std::uint32_t, bool>> todo{{root, false}};  // node, its children finished
  while (!todo.empty()) {
    const auto [m, children_done] = todo.back();
    const BuildNode& b = tree.nodes[m];
    if (!b.is_leaf() && !children_done) {
      todo.back().second = true;
      for (int side = 1; side >= 0; --side) {  // the left child on top: finished first
        const std::uint32_t c = b.child[side];
        claim(c);
        todo.push_back({c, false});
      }
      continue;
    }
    todo.pop_back();
    const float area = b.bounds.area();
    Subtree s;
    if (b.is_leaf()) {
      const bool fits = b.count <= kWidth && std::size_t(b.first) + b.count <= tree.prims.size();
      s.cost.fill(area);
      s.prims = static_cast<std::uint8_t>(std::min<std::uint32_t>(b.count, kWidth + 1));
      s.kinds = !fits ? 3 : tree.prims[b.first] < geometry.triangles.size() ? 1 : 2;
      plan.split_[m][0] = 1;
      done.push_back(s);
      continue;
    }
    const Subtree right = done.back();
    done.pop_back();
    const Subtree left = done.back();
    done.pop_back();
    s.prims = static_cast<std::uint8_t>(std::min(left.prims + right.prims, kWidth + 1));
    s.kinds = left.kinds | right.kinds;
    // shared[i]: both children below this node, i slots between them
    std::array<float, kWidth + 1> shared{};
    std::array<std::uint8_t, kWidth + 1> how{};
    for (int i = 2; i <= kWidth; ++i) {
      shared[i] = kInf;
      for (int k = 1; k < i; ++k) {
        const float c = left.cost[k - 1] + right.cost[i - k - 1];
        if (c < shared[i]) {
          shared[i] = c;
          how[i] = static_cast<std::uint8_t>(k | (i - k) << 4);
        }
      }
    }
    const float as_node = kCollapseNodeCost * area + shared[kWidth];
    const float as_block = s.prims <= kWidth && (s.kinds == 1 || s.kinds == 2) ? area : kInf;
    plan.split_[m][0] = as_block <= as_node;
    plan.wide_[m] = how[kWidth];
    float best = std::min(as_block, as_node);
    std::uint8_t best_how = 0;
    s.cost[0] = best;
    for (int i = 2; i <= kWidth; ++i) {
      if (shared[i] < best) {
        best = shared[i];
        best_how = how[i];
      }
      s.cost[i - 1] = best;
      plan.split_[m][i - 1] = best_how;
    }
    done.push_back(s);
  }
}

CollapsePlan plan_collapse(const BuildTree& tree, const Geometry& geometry) {
  CollapsePlan plan(tree.nodes.size());
  if (!tree.nodes.empty()) plan_subtree(tree, geometry, 0, plan);
  return plan;
}

}  // namespace rtcl
