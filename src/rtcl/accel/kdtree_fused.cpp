#include "rtcl/accel/kdtree_fused.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <utility>

namespace rtcl {

namespace {

bool is_leaf(const KdNode& n) { return (n.flags & 3u) == RTCL_KD_LEAF; }
bool is_empty_leaf(const KdNode& n) { return is_leaf(n) && n.data == 0; }

struct Fuser {
  const std::vector<KdNode>& nodes;
  const std::function<KdBox(std::size_t leaf, const KdBox& cell)>& leaf_bounds;
  std::vector<Bvh8Node> out;

  static double half_area(const KdBox& b) {
    const double x = b.upper[0] - b.lower[0], y = b.upper[1] - b.lower[1], z = b.upper[2] - b.lower[2];
    return x * y + y * z + z * x;
  }
  static void set_lane_box(Bvh8Node& f, int lane, const KdBox& b) {
    for (int a = 0; a < 3; ++a) {
      f.bounds[a][lane] = b.lower[a];
      f.bounds[3 + a][lane] = b.upper[a];
    }
  }

  // Emits the fused node of the kd subtree at nodes[root], whose cell is
  // `box`; returns its index and sets *bounds to the union of its lanes'.
  // The lanes: starting from the root, the frontier node with the largest
  // cell (surface area) is replaced by its children while that keeps at
  // most eight lanes; empty leaves take no lane.
  rtcl_i32 emit(std::size_t root, const KdBox& box, KdBox* bounds) {
    const std::size_t index = out.size();
    out.emplace_back();
    std::vector<std::pair<std::size_t, KdBox>> lanes{{root, box}};
    for (;;) {
      int widest = -1;
      double widest_area = -1.0;
      for (std::size_t k = 0; k < lanes.size(); ++k) {
        const auto& [n, cell] = lanes[k];
        if (is_leaf(nodes[n])) continue;
        const double area = half_area(cell);
        if (area > widest_area) widest = static_cast<int>(k), widest_area = area;
      }
      if (widest < 0) break;
      const auto [n, cell] = lanes[static_cast<std::size_t>(widest)];
      const KdNode& node = nodes[n];
      const rtcl_u32 axis = node.flags & 3u;
      const float split = std::bit_cast<float>(node.data);
      KdBox below = cell, above = cell;
      below.upper[axis] = split;
      above.lower[axis] = split;
      std::vector<std::pair<std::size_t, KdBox>> children;
      for (const auto& child : {std::pair{n + 1, below}, std::pair{std::size_t(node.flags >> 2), above}})
        if (!is_empty_leaf(nodes[child.first])) children.push_back(child);
      if (lanes.size() - 1 + children.size() > 8) break;
      lanes.erase(lanes.begin() + widest);
      lanes.insert(lanes.end(), children.begin(), children.end());
    }
    Bvh8Node f{};
    for (int k = 0; k < 8; ++k) {
      set_lane_box(f, k, KdBox::empty());
      f.child[k] = RTCL_KD_NO_CELL;
    }
    *bounds = KdBox::empty();
    for (std::size_t k = 0; k < lanes.size(); ++k) {
      const auto& [n, cell] = lanes[k];
      if (is_empty_leaf(nodes[n])) continue;
      KdBox lane_box;
      if (is_leaf(nodes[n])) {
        lane_box = leaf_bounds(n, cell);
        f.child[k] = ~static_cast<rtcl_i32>(n);
      } else {
        f.child[k] = emit(n, cell, &lane_box);
      }
      set_lane_box(f, static_cast<int>(k), lane_box);
      bounds->grow(lane_box);
    }
    out[index] = f;
    return static_cast<rtcl_i32>(index);
  }
};

}  // namespace

std::vector<Bvh8Node> fuse_kd_nodes(const std::vector<KdNode>& nodes, const KdHeader& header,
                                    const std::function<KdBox(std::size_t leaf, const KdBox& cell)>& leaf_bounds) {
  Fuser fuser{nodes, leaf_bounds, {}};
  KdBox root, bounds;
  for (int a = 0; a < 3; ++a) {
    root.lower[a] = header.lower[a];
    root.upper[a] = header.upper[a];
  }
  if (!nodes.empty()) fuser.emit(0, root, &bounds);
  return std::move(fuser.out);
}

}  // namespace rtcl
