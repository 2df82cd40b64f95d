#include "rtcl/accel/bvh_volumes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include <glm/glm.hpp>

#include "rtcl/error.hpp"

namespace rtcl {

namespace {

// Options at a node: boxes alone (0) or kind k's filter (1 + k).
constexpr int kOptions = 1 + kFilterKinds;

// The vertices of every triangle below child reference `ref`, each once
// (sorted); false when a sphere primitive lies below it (no filter for that
// child).
bool collect_vertices(const Bvh8& bvh, rtcl_i32 ref, std::vector<glm::vec3>& points) {
  points.clear();
  std::vector<rtcl_i32> todo{ref};
  while (!todo.empty()) {
    rtcl_i32 r = todo.back();
    todo.pop_back();
    if (r >= 0) {
      for (rtcl_i32 c : bvh.nodes[static_cast<std::size_t>(r)].child)
        if (c != RTCL_CHILD_EMPTY) todo.push_back(c);
      continue;
    }
    rtcl_i32 leaf = ~r;
    if (leaf & 1) return false;
    const TriangleBlock& block = bvh.blocks.triangles[static_cast<std::size_t>(leaf >> 1)];
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane)
      if (block.prim[lane] >= 0)
        for (int v = 0; v < 3; ++v) points.emplace_back(block.v[v][0][lane], block.v[v][1][lane], block.v[v][2][lane]);
  }
  auto less = [](const glm::vec3& a, const glm::vec3& b) {
    return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
  };
  std::sort(points.begin(), points.end(), less);
  points.erase(std::unique(points.begin(), points.end()), points.end());
  return !points.empty();
}

double box_area(const Aabb& b) {
  if (b.empty()) return 0.0;
  glm::dvec3 e = glm::dvec3(b.upper) - glm::dvec3(b.lower);
  return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
}

// What the bottom-up pass keeps per node.
struct NodeTable {
  std::array<std::optional<ChildVolumes>, RTCL_BLOCK_WIDTH> volumes;
  std::array<std::array<double, kOptions>, RTCL_BLOCK_WIDTH> slot_area{};  // per lane and option
  std::array<bool, kOptions> available{};
  std::array<double, kOptions> below{};  // sum over children of their cost at this option's areas
  double below_boxes = 0.0;              // the same, boxes only everywhere
};

}  // namespace

std::size_t BvhVolumeFilters::device_bytes() const {
  if (empty()) return 0;
  return filter_of.size() * sizeof(rtcl_i32) + spheres.size() * sizeof(Bvh8Spheres) +
         kdops.size() * sizeof(Bvh8Kdop) + obbs.size() * sizeof(Bvh8Obb);
}

BvhVolumeFilters choose_volume_filters(const Bvh8& bvh, const VolumeCosts& costs, const std::string& source) {
  for (float c : {costs.sphere, costs.kdop, costs.obb, costs.block})
    if (!(c >= 0.0f) || !std::isfinite(c))
      throw Error("bvh-mixed over " + source + ": test costs must be finite and >= 0 (sphere_cost " +
                  std::to_string(costs.sphere) + ", kdop_cost " + std::to_string(costs.kdop) + ", obb_cost " +
                  std::to_string(costs.obb) + ", block_cost " + std::to_string(costs.block) + ")");
  BvhVolumeFilters out;
  out.filter_of.assign(bvh.nodes.size(), RTCL_FILTER_NONE);
  if (bvh.nodes.empty()) return out;
  const double filter_cost[kOptions] = {0.0, costs.sphere, costs.kdop, costs.obb};

  std::vector<NodeTable> table(bvh.nodes.size());
  // A node's cost at entering area a: the cheapest available option.
  auto node_cost = [&](std::size_t n, double a) {
    double best = a + table[n].below[0];
    for (int o = 1; o < kOptions; ++o)
      if (table[n].available[static_cast<std::size_t>(o)])
        best = std::fmin(best, a * (1.0 + filter_cost[o]) + table[n].below[static_cast<std::size_t>(o)]);
    return best;
  };
  auto child_cost = [&](rtcl_i32 child, double a) {
    return child >= 0 ? node_cost(static_cast<std::size_t>(child), a) : a * costs.block;
  };
  auto child_cost_boxes = [&](rtcl_i32 child, double a) {
    return child >= 0 ? a + table[static_cast<std::size_t>(child)].below_boxes : a * costs.block;
  };

  std::vector<glm::vec3> points;
  for (std::size_t n = bvh.nodes.size(); n-- > 0;) {
    const Bvh8Node& node = bvh.nodes[n];
    NodeTable& t = table[n];
    t.available[0] = true;
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
      rtcl_i32 child = node.child[lane];
      if (child == RTCL_CHILD_EMPTY) continue;
      Aabb box = bvh8_lane_box(node, lane);
      auto& area = t.slot_area[static_cast<std::size_t>(lane)];
      area.fill(box_area(box));
      if (collect_vertices(bvh, child, points)) {
        const ChildVolumes& v = t.volumes[static_cast<std::size_t>(lane)].emplace(child_volumes(box, points, source));
        for (int k = 0; k < kFilterKinds; ++k)
          if (v.used[k]) {
            area[static_cast<std::size_t>(1 + k)] = v.area[k];
            t.available[static_cast<std::size_t>(1 + k)] = true;
          }
      }
      for (int o = 0; o < kOptions; ++o) t.below[static_cast<std::size_t>(o)] += child_cost(child, area[static_cast<std::size_t>(o)]);
      t.below_boxes += child_cost_boxes(child, area[0]);
    }
  }

  // Top-down: each node's option at the area its parent's choice gives it.
  Aabb root_box;
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane)
    if (bvh.nodes[0].child[lane] != RTCL_CHILD_EMPTY) root_box.grow(bvh8_lane_box(bvh.nodes[0], lane));
  double a_root = box_area(root_box);
  std::vector<double> entering(bvh.nodes.size(), 0.0);
  entering[0] = a_root;
  for (std::size_t n = 0; n < bvh.nodes.size(); ++n) {
    const NodeTable& t = table[n];
    double a = entering[n];
    int choice = 0;
    double best = a + t.below[0];
    for (int o = 1; o < kOptions; ++o) {
      double c = a * (1.0 + filter_cost[o]) + t.below[static_cast<std::size_t>(o)];
      if (t.available[static_cast<std::size_t>(o)] && c < best) {
        best = c;
        choice = o;
      }
    }
    if (n == 0) {
      double unit = a_root > 0.0 ? a_root : 1.0;
      out.chosen_cost = (a_root > 0.0 ? best : 1.0) / unit;
      out.aabb_cost = (a_root > 0.0 ? a + t.below_boxes : 1.0) / unit;
    }
    const Bvh8Node& node = bvh.nodes[n];
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane)
      if (node.child[lane] >= 0)
        entering[static_cast<std::size_t>(node.child[lane])] =
            t.slot_area[static_cast<std::size_t>(lane)][static_cast<std::size_t>(choice)];
    if (choice == 0) continue;
    int kind = choice - 1;
    std::size_t index = 0;
    Bvh8Spheres sphere{};
    Bvh8Kdop kdop{};
    Bvh8Obb obb{};
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
      const auto& slot = t.volumes[static_cast<std::size_t>(lane)];
      const ChildVolumes* v = slot ? &*slot : nullptr;
      if (v != nullptr && v->used[kind]) ++out.lanes[kind];
      if (kind == RTCL_FILTER_SPHERE) write_sphere_lane(sphere, lane, v);
      if (kind == RTCL_FILTER_KDOP) write_kdop_lane(kdop, lane, v);
      if (kind == RTCL_FILTER_OBB) write_obb_lane(obb, lane, v);
    }
    if (kind == RTCL_FILTER_SPHERE) index = out.spheres.size(), out.spheres.push_back(sphere);
    if (kind == RTCL_FILTER_KDOP) index = out.kdops.size(), out.kdops.push_back(kdop);
    if (kind == RTCL_FILTER_OBB) index = out.obbs.size(), out.obbs.push_back(obb);
    out.filter_of[n] = RTCL_FILTER_REF(kind, static_cast<rtcl_i32>(index));
  }
  return out;
}

}  // namespace rtcl
