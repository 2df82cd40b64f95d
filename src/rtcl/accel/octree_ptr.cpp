#include "rtcl/accel/octree_ptr.hpp"
#include "rtcl/accel/structure_kernels.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "rtcl/accel/octree.hpp"
#include "rtcl/error.hpp"

namespace rtcl {

std::size_t OctreePtr::bytes() const {
  return sizeof(OctreePtrHeader) + nodes.size() * sizeof(OctreeNode) + leaf_begin.size() * sizeof(rtcl_u32) +
         blocks.bytes() + block_boxes.size() * sizeof(BlockBox);
}

OctreePtr flatten_octree_ptr(const Geometry& geometry, OctreeBuild&& tree, const std::array<float, 3>& lower,
                             const std::array<float, 3>& upper) {
  OctreePtr out;
  for (int a = 0; a < 3; ++a) {
    out.header.lower[a] = lower[a];
    out.header.upper[a] = upper[a];
  }
  out.header.depth = tree.depth;
  out.ref_count = tree.ref_count;
  out.leaf_begin = {0, 0};
  const double widening = octree_widening(geometry);
  for (int r = 0; r < 6; ++r)
    for (int q = 0; q < RTCL_BLOCK_WIDTH; ++q) out.header.occupied_bounds[r][q] = r < 3 ? INFINITY : -INFINITY;
  // The root's child each node lies below (slot 0 for a leaf root); build
  // order puts parents first.
  std::vector<int> octant(tree.nodes.size(), 0);
  for (std::size_t i = 0; i < tree.nodes.size(); ++i)
    if (!tree.nodes[i].leaf())
      for (int q = 0; q < 8; ++q) octant[static_cast<std::size_t>(tree.nodes[i].child[q])] = i == 0 ? q : octant[i];
  // Build order (breadth first) keeps parents before children: an inner
  // node's index is its rank among the inner nodes, so one pass numbers them.
  std::vector<rtcl_i32> reference(tree.nodes.size());
  rtcl_i32 inner = 0;
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    OctreeBuildNode& node = tree.nodes[i];
    if (!node.leaf()) {
      reference[i] = inner++;
      continue;
    }
    if (node.refs.empty()) {
      reference[i] = RTCL_CHILD_EMPTY;
      continue;
    }
    reference[i] = ~static_cast<rtcl_i32>(out.leaf_begin.size() / 2 - 1);
    const std::size_t first_box = out.block_boxes.size();
    append_leaf_blocks(geometry, tree.ids, node, widening, out.blocks, out.block_boxes, out.leaf_begin);
    BlockBox content = leaf_sphere_box(geometry, node, widening);
    for (std::size_t b = first_box; b < out.block_boxes.size(); ++b) grow_box(content, out.block_boxes[b]);
    for (int r = 0; r < 6; ++r) {
      float& v = out.header.occupied_bounds[r][octant[i]];
      v = r < 3 ? std::min(v, content.bounds[r]) : std::max(v, content.bounds[r]);
    }
    std::vector<rtcl_i32>().swap(node.refs);
  }
  out.nodes.resize(static_cast<std::size_t>(inner));
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    const OctreeBuildNode& node = tree.nodes[i];
    if (node.leaf()) continue;
    OctreeNode& n = out.nodes[static_cast<std::size_t>(reference[i])];
    for (int a = 0; a < 3; ++a) n.split[a] = node.split[a];
    n.split[3] = 0.0f;
    for (int q = 0; q < 8; ++q) n.child[q] = reference[static_cast<std::size_t>(node.child[q])];
  }
  out.header.root = reference[0];
  out.header.leaf_count = static_cast<rtcl_u32>(out.leaf_begin.size() / 2 - 1);
  return out;
}

OctreePtr build_octree_ptr(const Geometry& geometry, const OctreePtrConfig& config) {
  OctreeBuildConfig build = octree_build_config(config, "octree-ptr");
  check_octree_config(build, kOctreePtrMaxDepth);
  OctreeHeader cube = octree_cube(geometry, config.max_depth);
  std::array<float, 3> lower{cube.lower[0], cube.lower[1], cube.lower[2]}, upper = octree_cube_upper(cube);
  return flatten_octree_ptr(
      geometry, build_octree_nodes(geometry, lower, upper, build, kOctreePtrMaxDepth, octree_centre_rule(cube)),
      lower, upper);
}

namespace {

std::vector<std::string> ptr_defines(const Geometry& geometry, const OctreePtr& tree) {
  std::vector<std::string> defines = primitive_defines(geometry);
  // 3 entries per level and one; two sizes, so that trees of other depths
  // share a program
  defines.push_back(std::string("RTCL_OCTREE_STACK=") + (tree.header.depth <= 10 ? "31" : "61"));
  return defines;
}

class OctreePtrAccel final : public Accel {
 public:
  OctreePtrAccel(const Device& device, const Geometry& geometry, std::string name, const OctreePtr& tree,
                 std::uint32_t occluder_run, AccelStats stats, const AccelConfig& config)
      : Accel(device, std::move(name), {"accel/octree_ptr.cl", 1, occluder_run_for(occluder_run, device.info())},
              std::nullopt, ptr_defines(geometry, tree), stats, config),
        header_(device.upload(&tree.header, sizeof tree.header, "octree header")),
        nodes_(tree.nodes.empty() ? device.upload(&kNoNode, sizeof kNoNode, "octree nodes")
                                  : device.upload(tree.nodes.data(), tree.nodes.size() * sizeof(OctreeNode),
                                                  "octree nodes")),
        leaf_begin_(device.upload(tree.leaf_begin.data(), tree.leaf_begin.size() * sizeof(rtcl_u32),
                                  "octree leaf offsets")),
        primitives_(upload(device, tree.blocks)),
        block_boxes_(upload_block_boxes(device, tree.block_boxes)) {}

 private:
  static constexpr OctreeNode kNoNode{};
  void set_structure_args(cl::Kernel& kernel, cl_uint first) const override {
    kernel.setArg(first, header_);
    kernel.setArg(first + 1, nodes_);
    kernel.setArg(first + 2, leaf_begin_);
    kernel.setArg(first + 3, primitives_.triangles);
    kernel.setArg(first + 4, primitives_.spheres);
    kernel.setArg(first + 5, block_boxes_);
  }

  cl::Buffer header_, nodes_, leaf_begin_;
  DevicePrimitives primitives_;
  cl::Buffer block_boxes_;
};

}  // namespace

std::unique_ptr<Accel> make_octree_ptr_from(const Device& device, const Geometry& geometry, std::string name,
                                            const OctreePtr& tree, std::uint32_t occluder_run, AccelStats stats,
                                            const AccelConfig& config) {
  stats.device_bytes = tree.bytes();
  stats.node_count = tree.nodes.size();
  stats.leaf_count = tree.blocks.triangles.size() + tree.blocks.spheres.size();
  return std::make_unique<OctreePtrAccel>(device, geometry, std::move(name), tree, occluder_run, stats, config);
}

std::unique_ptr<Accel> make_octree_ptr(const Device& device, const Geometry& geometry, const OctreePtrConfig& config,
                                       const AccelConfig& accel_config) {
  AccelStats stats;
  OctreePtr tree = timed_octree_build(device, geometry, config, build_octree_ptr, &stats);
  return make_octree_ptr_from(device, geometry, "octree-ptr", tree, config.occluder_run, stats, accel_config);
}

const StructureSpec& octree_ptr_structure() {
  static const StructureSpec spec{
      "octree-ptr",
      "octree with child pointers (the octree's tree), top-down traversal in ray order (Revelles et al. 2000)",
      octree_options(kOctreePtrMaxDepth, OctreePtrConfig{}.max_depth, OctreePtrConfig{}.leaf_size,
                     OctreePtrConfig{}.ref_budget)};
  return spec;
}

std::unique_ptr<Accel> make_octree_ptr_accel(const Device& device, const Geometry& geometry,
                                             const AccelConfig& config) {
  const AccelOptions& o = config.options;
  OctreePtrConfig tree;
  read_octree_options(o, &tree);
  return make_octree_ptr(device, geometry, tree, config);
}

}  // namespace rtcl
