#include "rtcl/accel/kdtree_fused.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <utility>

namespace rtcl {

namespace {

bool is_leaf(const KdNode& n) { return (n.flags & 3u) == RTCL_KD_LEAF; }

struct Fuser {
  const std::vector<KdNode>& nodes;
  const std::function<KdBox(std::size_t leaf, const KdBox& cell)>& leaf_bounds;
  std::vector<Bvh8Node> out;

  static KdBox cell_box(const Bvh8Node& f, int cell) {
    KdBox b;
    for (int a = 0; a < 3; ++a) {
      b.lower[a] = f.bounds[a][cell];
      b.upper[a] = f.bounds[3 + a][cell];
    }
    return b;
  }
  static void set_cell_box(Bvh8Node& f, int cell, const KdBox& b) {
    for (int a = 0; a < 3; ++a) {
      f.bounds[a][cell] = b.lower[a];
      f.bounds[3 + a][cell] = b.upper[a];
    }
  }

  // Emits the fused node of the kd subtree at nodes[root], whose cell is
  // `box`; returns its index and sets *bounds to the union of its cells'.
  rtcl_i32 emit(std::size_t root, const KdBox& box, KdBox* bounds) {
    const std::size_t index = out.size();
    out.emplace_back();
    Bvh8Node f{};
    for (int k = 0; k < 8; ++k) {
      for (int a = 0; a < 3; ++a) {
        f.bounds[a][k] = std::numeric_limits<float>::infinity();
        f.bounds[3 + a][k] = -std::numeric_limits<float>::infinity();
      }
      f.child[k] = RTCL_KD_NO_CELL;
    }
    std::vector<std::pair<int, std::size_t>> deeper;  // (cell, kd inner node at level 3)
    place(f, root, 0, 0, 1, box, deeper);
    for (const auto& [cell, node] : deeper) {
      KdBox b = cell_box(f, cell), tight;
      f.child[cell] = emit(node, b, &tight);
      set_cell_box(f, cell, tight);
    }
    *bounds = KdBox::empty();
    for (int k = 0; k < 8; ++k) bounds->grow(cell_box(f, k));
    out[index] = f;
    return static_cast<rtcl_i32>(index);
  }

  // Fills the cells [cell, cell + 2^(3 - level)) from kd node n, whose kd
  // cell is `box`. A leaf above level 3 takes the cell on its side `side`
  // of every level below it (the others stay empty).
  void place(Bvh8Node& f, std::size_t n, int level, int cell, int side, const KdBox& box,
             std::vector<std::pair<int, std::size_t>>& deeper) {
    const int half = level < 3 ? 1 << (2 - level) : 0;
    const KdNode& node = nodes[n];
    if (level == 3 || is_leaf(node)) {
      if (level < 3) {
        place(f, n, level + 1, cell + side * half, side, box, deeper);
        return;
      }
      if (is_leaf(node) && node.data == 0) return;
      if (is_leaf(node)) {
        set_cell_box(f, cell, leaf_bounds(n, box));
        f.child[cell] = ~static_cast<rtcl_i32>(n);
      } else {
        set_cell_box(f, cell, box);
        deeper.emplace_back(cell, n);
      }
      return;
    }
    const rtcl_u32 axis = node.flags & 3u;
    const float split = std::bit_cast<float>(node.data);
    KdBox below = box, above = box;
    below.upper[axis] = split;
    above.lower[axis] = split;
    place(f, n + 1, level + 1, cell, 0, below, deeper);
    place(f, node.flags >> 2, level + 1, cell + half, 1, above, deeper);
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
