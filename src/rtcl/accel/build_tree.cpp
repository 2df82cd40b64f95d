#include "rtcl/accel/build_tree.hpp"

#include <cmath>
#include <unordered_map>
#include <utility>

#include "rtcl/error.hpp"

namespace rtcl {

std::uint32_t BuildTree::depth() const {
  if (nodes.empty()) return 0;
  std::uint32_t deepest = 0;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> todo{{0u, 1u}};  // node, depth
  while (!todo.empty()) {
    auto [n, d] = todo.back();
    todo.pop_back();
    if (d > deepest) deepest = d;
    if (nodes[n].is_leaf()) continue;
    todo.push_back({nodes[n].child[0], d + 1});
    todo.push_back({nodes[n].child[1], d + 1});
  }
  return deepest;
}

BuildTree join(BuildTree a, BuildTree b) {
  if (b.empty()) return a;
  if (a.empty()) return b;
  auto b_node_offset = static_cast<std::uint32_t>(1 + a.nodes.size());
  auto b_prim_offset = static_cast<std::uint32_t>(a.prims.size());
  BuildTree out;
  out.nodes.reserve(1 + a.nodes.size() + b.nodes.size());
  BuildNode root;
  root.bounds = merge(a.nodes[0].bounds, b.nodes[0].bounds);
  root.child[0] = 1;
  root.child[1] = b_node_offset;
  out.nodes.push_back(root);
  for (BuildNode n : a.nodes) {
    if (!n.is_leaf()) {
      n.child[0] += 1;
      n.child[1] += 1;
    }
    out.nodes.push_back(n);
  }
  for (BuildNode n : b.nodes) {
    if (n.is_leaf()) {
      n.first += b_prim_offset;
    } else {
      n.child[0] += b_node_offset;
      n.child[1] += b_node_offset;
    }
    out.nodes.push_back(n);
  }
  out.prims = std::move(a.prims);
  out.prims.insert(out.prims.end(), b.prims.begin(), b.prims.end());
  return out;
}

void check_builder_sizes(std::span<const Aabb> bounds, std::span<const std::uint32_t> ids, const char* builder) {
  if (bounds.size() != ids.size())
    throw Error(std::string(builder) + ": " + std::to_string(bounds.size()) + " boxes but " +
                std::to_string(ids.size()) + " primitive ids");
  if (bounds.size() > 0x7fffffffu)
    throw Error(std::string(builder) + ": " + std::to_string(bounds.size()) + " primitives exceed 2^31 - 1");
}

Error builder_box_error(std::uint32_t id, const char* builder) {
  return Error(std::string(builder) + ": the box of primitive " + std::to_string(id) +
               " has a NaN or infinite coordinate or lower > upper");
}

void check_builder_input(std::span<const Aabb> bounds, std::span<const std::uint32_t> ids, const char* builder) {
  check_builder_sizes(bounds, ids, builder);
  for (std::size_t i = 0; i < bounds.size(); ++i) {
    const Aabb& b = bounds[i];
    bool ok = true;
    for (int a = 0; a < 3; ++a) ok = ok && std::isfinite(b.lower[a]) && std::isfinite(b.upper[a]) && b.lower[a] <= b.upper[a];
    if (!ok) throw builder_box_error(ids[i], builder);
  }
}

std::string check(const BuildTree& tree, std::span<const Aabb> bounds, std::span<const std::uint32_t> ids,
                  std::uint32_t max_leaf) {
  if (bounds.size() != ids.size()) return "bounds and ids differ in length";
  if (tree.empty()) return ids.empty() ? "" : "empty tree for " + std::to_string(ids.size()) + " primitives";
  std::unordered_map<std::uint32_t, std::size_t> position;
  for (std::size_t i = 0; i < ids.size(); ++i)
    if (!position.emplace(ids[i], i).second) return "id " + std::to_string(ids[i]) + " given twice";
  std::vector<char> node_seen(tree.nodes.size(), 0), prim_seen(ids.size(), 0);
  std::size_t prims_in_leaves = 0;
  std::vector<std::uint32_t> todo{0};
  while (!todo.empty()) {
    std::uint32_t n = todo.back();
    todo.pop_back();
    std::string where = "node " + std::to_string(n);
    if (n >= tree.nodes.size()) return where + " does not exist";
    if (node_seen[n]++) return where + " is reached twice";
    const BuildNode& node = tree.nodes[n];
    if (node.is_leaf()) {
      if (node.count > max_leaf) return where + " holds " + std::to_string(node.count) + " primitives";
      if (std::size_t(node.first) + node.count > tree.prims.size()) return where + " indexes past prims";
      for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
        auto it = position.find(tree.prims[k]);
        if (it == position.end()) return where + " holds unknown id " + std::to_string(tree.prims[k]);
        if (prim_seen[it->second]++) return "id " + std::to_string(tree.prims[k]) + " is in two leaves";
        if (!node.bounds.contains(bounds[it->second]))
          return where + " does not contain the box of id " + std::to_string(tree.prims[k]);
        ++prims_in_leaves;
      }
      continue;
    }
    for (std::uint32_t c : node.child) {
      if (c >= tree.nodes.size()) return where + " has child " + std::to_string(c) + " that does not exist";
      if (!node.bounds.contains(tree.nodes[c].bounds))
        return where + " does not contain its child " + std::to_string(c);
      todo.push_back(c);
    }
  }
  if (prims_in_leaves != ids.size())
    return std::to_string(ids.size() - prims_in_leaves) + " primitives are in no leaf";
  for (std::size_t n = 0; n < node_seen.size(); ++n)
    if (!node_seen[n]) return "node " + std::to_string(n) + " is unreachable";
  return "";
}

}  // namespace rtcl
