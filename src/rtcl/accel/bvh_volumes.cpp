#include "rtcl/accel/bvh_volumes.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <numbers>

#include <glm/glm.hpp>

#include "rtcl/bounds/sphere_bounds.hpp"
#include "rtcl/error.hpp"

namespace rtcl {

namespace {

// The vertices of every triangle below child reference `ref`; false when a
// sphere primitive lies below it (no sphere filter for that child).
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
  return !points.empty();
}

Aabb lane_box(const Bvh8Node& node, int lane) {
  return {{node.bounds[0][lane], node.bounds[1][lane], node.bounds[2][lane]},
          {node.bounds[3][lane], node.bounds[4][lane], node.bounds[5][lane]}};
}

// The record's radius: the sphere's, plus the ray-independent part of the
// filter's margin (kernels/shared/sphere_filter8.h), rounded up to float.
float widened_radius(const BoundingSphere& s) {
  double r = static_cast<double>(s.radius) + 16.0 * FLT_EPSILON * static_cast<double>(s.reach);
  auto f = static_cast<float>(r);
  return static_cast<double>(f) < r ? std::nextafter(f, FLT_MAX) : f;
}

}  // namespace

BvhSphereFilters choose_sphere_filters(const Bvh8& bvh, const VolumeCosts& costs, const std::string& source) {
  for (float c : {costs.sphere, costs.block})
    if (!(c >= 0.0f) || !std::isfinite(c))
      throw Error("bvh-mixed over " + source + ": test costs must be finite and >= 0 (sphere_cost " +
                  std::to_string(costs.sphere) + ", block_cost " + std::to_string(costs.block) + ")");
  BvhSphereFilters out;
  out.sphere_of.assign(bvh.nodes.size(), -1);
  std::vector<double> cost(bvh.nodes.size(), 0.0), plain_cost(bvh.nodes.size(), 0.0);
  std::vector<glm::vec3> points;
  const double box_cost = 1.0;
  for (std::size_t n = bvh.nodes.size(); n-- > 0;) {
    const Bvh8Node& node = bvh.nodes[n];
    Aabb all;
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane)
      if (node.child[lane] != RTCL_CHILD_EMPTY) all = merge(all, lane_box(node, lane));
    double parent_area = all.area();
    Bvh8Spheres record;
    double plain = box_cost, plain_all = box_cost, filtered = box_cost + costs.sphere;
    std::size_t lanes = 0;
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
      record.cx[lane] = record.cy[lane] = record.cz[lane] = 0.0f;
      record.r[lane] = -1.0f;
      rtcl_i32 child = node.child[lane];
      if (child == RTCL_CHILD_EMPTY) continue;
      double below = child >= 0 ? cost[static_cast<std::size_t>(child)] : costs.block;
      double below_plain = child >= 0 ? plain_cost[static_cast<std::size_t>(child)] : costs.block;
      double box_area = lane_box(node, lane).area();
      double p = parent_area > 0.0 ? box_area / parent_area : 1.0;
      plain += p * below;
      plain_all += p * below_plain;
      double p_filtered = p;
      if (parent_area > 0.0 && collect_vertices(bvh, child, points)) {
        BoundingSphere s = exact_sphere(points, source);
        float r = widened_radius(s);
        double sphere_area = 4.0 * std::numbers::pi * static_cast<double>(r) * r;
        if (sphere_area < box_area) {
          record.cx[lane] = s.center.x;
          record.cy[lane] = s.center.y;
          record.cz[lane] = s.center.z;
          record.r[lane] = r;
          p_filtered = sphere_area / parent_area;
          ++lanes;
        }
      }
      filtered += p_filtered * below;
    }
    plain_cost[n] = plain_all;
    if (lanes > 0 && filtered < plain) {
      out.sphere_of[n] = static_cast<rtcl_i32>(out.records.size());
      out.records.push_back(record);
      out.sphere_lanes += lanes;
      cost[n] = filtered;
    } else {
      cost[n] = plain;
    }
  }
  if (!bvh.nodes.empty()) {
    out.aabb_cost = plain_cost[0];
    out.chosen_cost = cost[0];
  }
  return out;
}

}  // namespace rtcl
