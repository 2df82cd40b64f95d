#include "rtcl/accel/octree_build.hpp"
#include "rtcl/accel/structure_kernels.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <span>

#include "rtcl/bounds/overlap.hpp"
#include "rtcl/error.hpp"

namespace rtcl {

namespace {

PrimitiveBounds primitive_bounds(const Geometry& geometry, const std::vector<std::uint32_t>& ids) {
  PrimitiveBounds b;
  b.triangle_count = ids.size() - geometry.spheres.size();
  b.lower.resize(ids.size());
  b.upper.resize(ids.size());
  for (std::size_t k = 0; k < b.triangle_count; ++k) {
    const glm::uvec3& t = geometry.triangles[ids[k]];
    glm::dvec3 p(geometry.vertices[t.x]), q(geometry.vertices[t.y]), r(geometry.vertices[t.z]);
    b.lower[k] = glm::min(p, glm::min(q, r));
    b.upper[k] = glm::max(p, glm::max(q, r));
  }
  for (std::size_t j = 0; j < geometry.spheres.size(); ++j) {
    const Sphere& s = geometry.spheres[j];
    b.lower[b.triangle_count + j] = glm::dvec3(s.center) - double(s.radius);
    b.upper[b.triangle_count + j] = glm::dvec3(s.center) + double(s.radius);
  }
  return b;
}

// Whether the primitive `ref` meets the closed box [lo, hi] (already widened).
bool overlaps(const Geometry& geometry, const std::vector<std::uint32_t>& ids, const PrimitiveBounds& bounds,
              rtcl_i32 ref, const glm::dvec3& lo, const glm::dvec3& hi) {
  std::size_t i = bounds.index(ref);
  const glm::dvec3 &pl = bounds.lower[i], &pu = bounds.upper[i];
  for (int a = 0; a < 3; ++a)
    if (pu[a] < lo[a] || pl[a] > hi[a]) return false;
  bool inside = true;
  for (int a = 0; a < 3; ++a) inside = inside && pl[a] >= lo[a] && pu[a] <= hi[a];
  if (inside) return true;
  if (ref >= 0) {
    const glm::uvec3& t = geometry.triangles[ids[ref]];
    return triangle_box_overlap(glm::dvec3(geometry.vertices[t.x]), glm::dvec3(geometry.vertices[t.y]),
                                glm::dvec3(geometry.vertices[t.z]), 0.5 * (lo + hi), 0.5 * (hi - lo));
  }
  const Sphere& s = geometry.spheres[~ref];
  return sphere_box_overlap(glm::dvec3(s.center), s.radius, lo, hi);
}

double area(const std::array<double, 3>& e) { return 2.0 * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0]); }

// The cost test of OctreeBuildConfig::split_cost.
bool pays(const OctreeBuildNode& node, const std::array<float, 3>& s, const std::array<std::vector<rtcl_i32>, 8>& parts,
          double split_cost) {
  std::array<double, 3> e;
  for (int a = 0; a < 3; ++a) e[a] = double(node.upper[a]) - double(node.lower[a]);
  double whole = area(e);
  if (!(whole > 0.0)) return false;
  double cost = split_cost;
  for (int q = 0; q < 8; ++q) {
    std::array<double, 3> c;
    for (int a = 0; a < 3; ++a)
      c[a] = (q >> a) & 1 ? double(node.upper[a]) - double(s[a]) : double(s[a]) - double(node.lower[a]);
    cost += area(c) / whole * double(parts[q].size());
  }
  return cost < double(node.refs.size());
}

std::string options_text(const OctreeBuildConfig& c) {
  return "depth=" + std::to_string(c.max_depth) + ",leaf_size=" + std::to_string(c.leaf_size);
}

[[noreturn]] void too_large(const Geometry& g, const OctreeBuildConfig& c, const std::string& what,
                            std::uint64_t bytes) {
  throw Error(c.structure + " over " + g.source + ": " + options_text(c) + ": " + what + " need " +
              std::to_string(bytes) + " bytes, more than the device's largest buffer (" +
              std::to_string(c.max_alloc_bytes) +
              " bytes, CL_DEVICE_MAX_MEM_ALLOC_SIZE); use a smaller depth or a larger leaf_size");
}

}  // namespace

double scene_magnitude(const Geometry& geometry) {
  Aabb box = geometry.bounds();
  double magnitude = 0.0;
  for (int a = 0; a < 3; ++a)
    magnitude = std::max({magnitude, std::fabs(double(box.lower[a])), std::fabs(double(box.upper[a]))});
  return magnitude;
}

double octree_widening(const Geometry& geometry) { return 64.0 * FLT_EPSILON * scene_magnitude(geometry) + double(FLT_MIN); }

double octree_padding(const Geometry& geometry) {
  return std::max(16.0 * FLT_EPSILON * scene_magnitude(geometry), static_cast<double>(FLT_MIN));
}

void append_leaf_blocks(const Geometry& geometry, const std::vector<std::uint32_t>& ids,
                        const OctreeBuildNode& node, double widening, PrimitiveBlocks& blocks,
                        std::vector<BlockBox>& boxes, std::vector<rtcl_u32>& leaf_begin) {
  const std::uint32_t triangle_count = static_cast<std::uint32_t>(geometry.triangles.size());
  std::vector<std::uint32_t> triangles, spheres;
  for (rtcl_i32 r : node.refs) (r >= 0 ? triangles : spheres).push_back(r >= 0 ? ids[r] : triangle_count + std::uint32_t(~r));
  auto corner = [&](std::uint32_t id, int v) { return geometry.vertices[geometry.triangles[id][v]]; };
  for (std::size_t k = 0; k < triangles.size(); k += RTCL_BLOCK_WIDTH) {
    std::span<const std::uint32_t> block = std::span(triangles).subspan(k, std::min<std::size_t>(RTCL_BLOCK_WIDTH, triangles.size() - k));
    blocks.append(geometry, block);
    BlockBox box;
    for (int a = 0; a < 3; ++a) {
      float lo = INFINITY, hi = -INFINITY;
      for (std::uint32_t id : block)
        for (int v = 0; v < 3; ++v) {
          lo = std::min(lo, corner(id, v)[a]);
          hi = std::max(hi, corner(id, v)[a]);
        }
      // the widened cell, rounded outwards to float
      float cell_lo = std::nextafter(static_cast<float>(double(node.lower[a]) - widening), -INFINITY);
      float cell_hi = std::nextafter(static_cast<float>(double(node.upper[a]) + widening), INFINITY);
      box.bounds[a] = std::max(lo, cell_lo);
      box.bounds[3 + a] = std::min(hi, cell_hi);
    }
    boxes.push_back(box);
  }
  for (std::size_t k = 0; k < spheres.size(); k += RTCL_BLOCK_WIDTH)
    blocks.append(geometry, std::span(spheres).subspan(k, std::min<std::size_t>(RTCL_BLOCK_WIDTH, spheres.size() - k)));
  leaf_begin.push_back(static_cast<rtcl_u32>(blocks.triangles.size()));
  leaf_begin.push_back(static_cast<rtcl_u32>(blocks.spheres.size()));
}

BlockBox leaf_sphere_box(const Geometry& geometry, const OctreeBuildNode& node, double widening) {
  BlockBox box{{INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY}};
  for (rtcl_i32 r : node.refs) {
    if (r >= 0) continue;
    const Sphere& s = geometry.spheres[std::size_t(~r)];
    for (int a = 0; a < 3; ++a) {
      double lo = std::max(double(s.center[a]) - double(s.radius), double(node.lower[a]) - widening);
      double hi = std::min(double(s.center[a]) + double(s.radius), double(node.upper[a]) + widening);
      box.bounds[a] = std::min(box.bounds[a], std::nextafter(static_cast<float>(lo), -INFINITY));
      box.bounds[3 + a] = std::max(box.bounds[3 + a], std::nextafter(static_cast<float>(hi), INFINITY));
    }
  }
  return box;
}

void grow_box(BlockBox& box, const BlockBox& other) {
  for (int a = 0; a < 3; ++a) {
    box.bounds[a] = std::min(box.bounds[a], other.bounds[a]);
    box.bounds[3 + a] = std::max(box.bounds[3 + a], other.bounds[3 + a]);
  }
}

cl::Buffer upload_block_boxes(const Device& device, const std::vector<BlockBox>& boxes) {
  static const BlockBox none{};
  return boxes.empty() ? device.upload(&none, sizeof none, "octree block boxes")
                       : device.upload(boxes.data(), boxes.size() * sizeof(BlockBox), "octree block boxes");
}

std::vector<OptionSpec> octree_options(int max_depth, int depth, std::size_t leaf_size, double ref_budget,
                                       std::vector<OptionSpec> extra) {
  std::vector<OptionSpec> out = {
      {"depth", OptionType::integer, std::int64_t(depth), 0, double(max_depth), false,
       "maximum depth (levels below the root): deeper trees make shorter leaf lists, more nodes to walk and "
       "more references"},
      {"leaf_size", OptionType::integer, std::int64_t(leaf_size), 1, 1 << 20, false,
       "k: a node with at most k primitives is a leaf; smaller k makes more, smaller leaves"},
      {"ref_budget", OptionType::real, ref_budget, 1, 1e6, false,
       "references per primitive the tree may hold: splits past it are not made (bounds memory where surfaces "
       "meet along a line or at a point)"}};
  out.insert(out.end(), extra.begin(), extra.end());
  out.push_back(occluder_run_option());
  return out;
}

void check_octree_config(const OctreeBuildConfig& config, int max_depth_limit) {
  if (config.max_depth < 0 || config.max_depth > max_depth_limit)
    throw Error(config.structure + ": depth=" + std::to_string(config.max_depth) + ": must be in [0, " +
                std::to_string(max_depth_limit) + "] (what its " +
                (config.structure == "octree" ? "64-bit node codes" : "traversal stack") + " can hold)");
  if (config.leaf_size < 1)
    throw Error(config.structure + ": leaf_size=" + std::to_string(config.leaf_size) + ": must be >= 1");
  if (!(config.ref_budget >= 1.0) || !std::isfinite(config.ref_budget))
    throw Error(config.structure + ": ref_budget=" + std::to_string(config.ref_budget) + ": must be >= 1");
}

OctreeBuild build_octree_nodes(const Geometry& geometry, const std::array<float, 3>& lower,
                               const std::array<float, 3>& upper, const OctreeBuildConfig& config,
                               int max_depth_limit, const OctreeSplitRule& rule) {
  check_octree_config(config, max_depth_limit);
  std::vector<std::uint32_t> ids = stored_primitives(geometry);
  PrimitiveBounds bounds = primitive_bounds(geometry, ids);
  const double widen = octree_widening(geometry);
  const std::size_t max_refs = config.max_alloc_bytes ? config.max_alloc_bytes / sizeof(rtcl_i32) : SIZE_MAX;
  const double budget = std::max(1.0, config.ref_budget) * static_cast<double>(ids.size());
  const std::size_t max_nodes = config.max_alloc_bytes ? config.max_alloc_bytes / sizeof(OctreeNode) : SIZE_MAX;

  OctreeBuild out;
  OctreeBuildNode root;
  root.lower = lower;
  root.upper = upper;
  for (std::size_t k = 0; k < bounds.triangle_count; ++k) root.refs.push_back(static_cast<rtcl_i32>(k));
  for (std::size_t j = 0; j < geometry.spheres.size(); ++j) root.refs.push_back(~static_cast<rtcl_i32>(j));
  out.nodes.push_back(std::move(root));
  std::size_t pending_refs = out.nodes[0].refs.size();
  if (pending_refs > max_refs)
    too_large(geometry, config, std::to_string(pending_refs) + " references", pending_refs * sizeof(rtcl_i32));

  // Breadth first: nodes[i] is final once visited; children are appended.
  for (std::size_t i = 0; i < out.nodes.size(); ++i) {
    OctreeBuildNode& node = out.nodes[i];
    out.depth = std::max(out.depth, node.level);
    bool split = node.level < config.max_depth && node.refs.size() > config.leaf_size;
    std::array<std::vector<rtcl_i32>, 8> parts;
    std::array<float, 3> s{};
    if (split) {
      s = rule(node, node.refs, bounds);
      bool progress = false;
      for (int q = 0; q < 8; ++q) {
        glm::dvec3 lo, hi;
        for (int a = 0; a < 3; ++a) {
          bool up = (q >> a) & 1;
          lo[a] = double(up ? s[a] : node.lower[a]) - widen;
          hi[a] = double(up ? node.upper[a] : s[a]) + widen;
        }
        for (rtcl_i32 r : node.refs)
          if (overlaps(geometry, ids, bounds, r, lo, hi)) parts[q].push_back(r);
        progress = progress || parts[q].size() < node.refs.size();
      }
      std::size_t added = 0;
      for (const auto& part : parts) added += part.size();
      split = progress && out.ref_count + pending_refs - node.refs.size() + added <= budget &&
              (config.split_cost <= 0.0 || pays(node, s, parts, config.split_cost));
    }
    if (!split) {
      out.ref_count += node.refs.size();
      out.filled_leaves += !node.refs.empty();
      continue;
    }
    node.split = s;
    pending_refs -= node.refs.size();
    std::vector<rtcl_i32>().swap(node.refs);
    const OctreeBuildNode parent = node;  // copied: push_back below may move nodes
    std::uint32_t half = parent.level < 32 ? (1u << (std::max(0, config.max_depth - parent.level - 1))) : 0;
    for (int q = 0; q < 8; ++q) {
      OctreeBuildNode c;
      c.level = parent.level + 1;
      c.digits = (parent.digits << 3) | std::uint64_t(q);
      for (int a = 0; a < 3; ++a) {
        bool up = (q >> a) & 1;
        c.lower[a] = up ? parent.split[a] : parent.lower[a];
        c.upper[a] = up ? parent.upper[a] : parent.split[a];
        c.lattice[a] = parent.lattice[a] + (up ? half : 0);
      }
      pending_refs += parts[q].size();
      c.refs = std::move(parts[q]);
      out.nodes[i].child[q] = static_cast<std::int32_t>(out.nodes.size());
      out.nodes.push_back(std::move(c));
    }
    if (out.ref_count + pending_refs > max_refs)
      too_large(geometry, config, "more than " + std::to_string(max_refs) + " references",
                std::uint64_t(out.ref_count + pending_refs) * sizeof(rtcl_i32));
    if (out.nodes.size() / 8 > max_nodes)
      too_large(geometry, config, "more than " + std::to_string(max_nodes) + " nodes",
                std::uint64_t(out.nodes.size() / 8) * sizeof(OctreeNode));
  }
  out.blocks = in_order_blocks(geometry, ids);
  out.ids = std::move(ids);
  return out;
}

}  // namespace rtcl
