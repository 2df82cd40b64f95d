#include "rtcl/accel/octree.hpp"
#include "rtcl/accel/structure_kernels.hpp"

#include <algorithm>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "rtcl/error.hpp"

namespace rtcl {

namespace {

// Lattice plane n on axis a, exactly as the kernel computes it.
float plane(const OctreeHeader& g, int a, std::uint64_t n) { return g.lower[a] + static_cast<float>(n) * g.cell; }

// Buckets over the first T digits: about one per two leaves, T <= min(N, 7).
int bucket_digits(std::size_t leaves, int depth) {
  int t = 0;
  while (t < std::min(depth, 7) && (std::size_t(8) << (3 * t)) <= 2 * leaves) ++t;
  return t;
}

}  // namespace

std::size_t Octree::bytes() const {
  return sizeof(OctreeHeader) + codes.size() * sizeof(std::uint64_t) + leaf_begin.size() * sizeof(rtcl_u32) +
         bucket_begin.size() * sizeof(rtcl_u32) + blocks.bytes() +
         block_boxes.size() * sizeof(BlockBox);
}

OctreeHeader octree_cube(const Geometry& geometry, int depth) {
  Aabb box = geometry.bounds();
  double pad = octree_padding(geometry);
  OctreeHeader g{};
  g.depth = depth;
  double side = 0.0, hi[3];
  for (int a = 0; a < 3; ++a) {
    // Rounded outwards: the cube contains the padded scene box.
    g.lower[a] = std::nextafter(static_cast<float>(box.lower[a] - pad), -std::numeric_limits<float>::infinity());
    hi[a] = double(box.upper[a]) + pad;
    side = std::max(side, hi[a] - double(g.lower[a]));
  }
  const std::uint64_t n = std::uint64_t(1) << depth;
  g.cell = std::nextafter(static_cast<float>(side / double(n)), std::numeric_limits<float>::infinity());
  for (int a = 0; a < 3; ++a)
    while (double(plane(g, a, n)) < hi[a]) g.cell = std::nextafter(g.cell, FLT_MAX);
  return g;
}

std::uint64_t octree_point_code(const std::array<std::uint32_t, 3>& point, int depth) {
  std::uint64_t code = 0;
  for (int l = 1; l <= depth; ++l) {
    int bit = depth - l;
    std::uint64_t q = ((point[0] >> bit) & 1u) | (((point[1] >> bit) & 1u) << 1) | (((point[2] >> bit) & 1u) << 2);
    code = (code << 4) | q;
  }
  return code;
}

std::uint64_t octree_node_code(std::uint64_t point_code, int level, int depth) {
  int rest = 4 * (depth - level);
  std::uint64_t pad = rest >= 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << rest) - 1;
  return point_code | pad;
}

std::array<std::uint32_t, 3> octree_lower_corner(std::uint64_t code, int level, int depth) {
  std::array<std::uint32_t, 3> p{0, 0, 0};
  for (int l = 1; l <= level; ++l) {
    std::uint64_t q = (code >> (4 * (depth - l))) & 0xf;
    for (int a = 0; a < 3; ++a) p[a] |= std::uint32_t((q >> a) & 1u) << (depth - l);
  }
  return p;
}

OctreeSplitRule octree_centre_rule(const OctreeHeader& cube) {
  return [cube](const OctreeBuildNode& node, const std::vector<rtcl_i32>&, const PrimitiveBounds&) {
    std::uint64_t half = std::uint64_t(1) << (cube.depth - node.level - 1);
    return std::array<float, 3>{plane(cube, 0, node.lattice[0] + half), plane(cube, 1, node.lattice[1] + half),
                                plane(cube, 2, node.lattice[2] + half)};
  };
}

std::array<float, 3> octree_cube_upper(const OctreeHeader& cube) {
  std::uint64_t n = std::uint64_t(1) << cube.depth;
  return {plane(cube, 0, n), plane(cube, 1, n), plane(cube, 2, n)};
}

Octree build_octree(const Geometry& geometry, const OctreeConfig& config) {
  OctreeBuildConfig build = octree_build_config(config, "octree");
  check_octree_config(build, RTCL_OCTREE_MAX_DEPTH);
  Octree out;
  out.header = octree_cube(geometry, config.max_depth);
  std::array<float, 3> lower{out.header.lower[0], out.header.lower[1], out.header.lower[2]};
  OctreeBuild tree = build_octree_nodes(geometry, lower, octree_cube_upper(out.header), build, RTCL_OCTREE_MAX_DEPTH,
                                        octree_centre_rule(out.header));
  out.node_count = tree.nodes.size();

  // The table: leaves with primitives, sorted by code.
  const int n = config.max_depth;
  std::vector<std::pair<std::uint64_t, std::size_t>> leaves;
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    const OctreeBuildNode& node = tree.nodes[i];
    if (!node.leaf() || node.refs.empty()) continue;
    std::uint64_t code = 0;
    for (int l = 0; l < node.level; ++l) code = (code << 4) | ((node.digits >> (3 * (node.level - 1 - l))) & 7u);
    code <<= 4 * (n - node.level);
    leaves.push_back({octree_node_code(code, node.level, n), i});
  }
  std::sort(leaves.begin(), leaves.end());
  out.codes.reserve(leaves.size());
  out.leaf_begin.reserve(2 * leaves.size() + 2);
  out.leaf_begin = {0, 0};
  const double widening = octree_widening(geometry);
  out.ref_count = tree.ref_count;
  for (const auto& [code, i] : leaves) {
    out.codes.push_back(code);
    append_leaf_blocks(geometry, tree.ids, tree.nodes[i], widening, out.blocks, out.block_boxes, out.leaf_begin);
    std::vector<rtcl_i32>().swap(tree.nodes[i].refs);
  }
  out.header.leaf_count = static_cast<rtcl_u32>(out.codes.size());

  // Buckets: bucket b (the first T digits, base 8) starts at the first code
  // not below b's digits followed by zeros.
  int t = config.buckets ? bucket_digits(out.codes.size(), n) : 0;
  out.header.top_digits = t;
  std::size_t buckets = std::size_t(1) << (3 * t);
  out.bucket_begin.resize(buckets + 1);
  for (std::size_t b = 0; b < buckets; ++b) {
    std::uint64_t prefix = 0;
    for (int l = 0; l < t; ++l) prefix = (prefix << 4) | ((b >> (3 * (t - 1 - l))) & 7u);
    prefix = n - t < 16 ? prefix << (4 * (n - t)) : 0;  // t = 0 at depth 16: no digits, shift would be 64
    out.bucket_begin[b] = static_cast<rtcl_u32>(std::lower_bound(out.codes.begin(), out.codes.end(), prefix) -
                                                out.codes.begin());
  }
  out.bucket_begin[buckets] = out.header.leaf_count;
  if (config.max_alloc_bytes && out.codes.size() * sizeof(std::uint64_t) > config.max_alloc_bytes)
    throw Error("octree over " + geometry.source + ": depth=" + std::to_string(n) + ",leaf_size=" +
                std::to_string(config.leaf_size) + ": the code table needs " +
                std::to_string(out.codes.size() * sizeof(std::uint64_t)) +
                " bytes, more than the device's largest buffer (" + std::to_string(config.max_alloc_bytes) +
                " bytes, CL_DEVICE_MAX_MEM_ALLOC_SIZE); use a smaller depth or a larger leaf_size");
  return out;
}

namespace {

class OctreeAccel final : public Accel {
 public:
  OctreeAccel(const Device& device, const Geometry& geometry, const Octree& tree, std::uint32_t occluder_run,
              AccelStats stats, const AccelConfig& config)
      : Accel(device, "octree", {"accel/octree.cl", 1, occluder_run_for(occluder_run, device.info())}, std::nullopt,
              primitive_defines(geometry), stats, config),
        header_(device.upload(&tree.header, sizeof tree.header, "octree header")),
        codes_(tree.codes.empty() ? device.upload(&kNoCode, sizeof kNoCode, "octree codes")
                                  : device.upload(tree.codes.data(), tree.codes.size() * sizeof(std::uint64_t),
                                                  "octree codes")),
        leaf_begin_(device.upload(tree.leaf_begin.data(), tree.leaf_begin.size() * sizeof(rtcl_u32),
                                  "octree leaf offsets")),
        bucket_begin_(device.upload(tree.bucket_begin.data(), tree.bucket_begin.size() * sizeof(rtcl_u32),
                                    "octree buckets")),
        primitives_(upload(device, tree.blocks)),
        block_boxes_(upload_block_boxes(device, tree.block_boxes)) {}

 private:
  static constexpr std::uint64_t kNoCode = 0;

  void set_structure_args(cl::Kernel& kernel, cl_uint first) const override {
    kernel.setArg(first, header_);
    kernel.setArg(first + 1, codes_);
    kernel.setArg(first + 2, leaf_begin_);
    kernel.setArg(first + 3, bucket_begin_);
    kernel.setArg(first + 4, primitives_.triangles);
    kernel.setArg(first + 5, primitives_.spheres);
    kernel.setArg(first + 6, block_boxes_);
  }

  cl::Buffer header_, codes_, leaf_begin_, bucket_begin_;
  DevicePrimitives primitives_;
  cl::Buffer block_boxes_;
};

}  // namespace

std::unique_ptr<Accel> make_octree(const Device& device, const Geometry& geometry, const OctreeConfig& config,
                                   const AccelConfig& accel_config) {
  AccelStats stats;
  Octree tree = timed_octree_build(device, geometry, config, build_octree, &stats);
  stats.device_bytes = tree.bytes();
  stats.node_count = tree.node_count;
  stats.leaf_count = tree.blocks.triangles.size() + tree.blocks.spheres.size();
  return std::make_unique<OctreeAccel>(device, geometry, tree, config.occluder_run, stats, accel_config);
}

const StructureSpec& octree_structure() {
  static const StructureSpec spec{
      "octree",
      "octree of node codes (lecture), traversal by longest code match and cell exit points in lattice coordinates",
      octree_options(RTCL_OCTREE_MAX_DEPTH, OctreeConfig{}.max_depth, OctreeConfig{}.leaf_size,
                     OctreeConfig{}.ref_budget,
                     {{"buckets", OptionType::boolean, OctreeConfig{}.buckets, 0, 0, false,
                       "index the code table by its first digits before the binary search (false: search the "
                       "whole table)"}})};
  return spec;
}

std::unique_ptr<Accel> make_octree_accel(const Device& device, const Geometry& geometry, const AccelConfig& config) {
  const AccelOptions& o = config.options;
  OctreeConfig tree;
  read_octree_options(o, &tree);
  tree.buckets = o.boolean("buckets");
  return make_octree(device, geometry, tree, config);
}

}  // namespace rtcl
