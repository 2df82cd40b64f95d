#include "rtcl/accel/kdtree_nodes.hpp"
#include "rtcl/accel/structure_kernels.hpp"

#include "rtcl/accel/kdtree_fused.hpp"

#include <algorithm>
#include <bit>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

#include "rtcl/bounds/clip.hpp"
#include "rtcl/error.hpp"

namespace rtcl {

namespace {

// Node and reference indices share a 32-bit word with the 2 axis bits.
constexpr std::size_t kMaxIndex = std::size_t(1) << 30;
// Positions past the last reference lane: a float8 run starting at the last
// reference stays inside its row.
constexpr std::size_t kLanePadding = RTCL_BLOCK_WIDTH;

[[noreturn]] void too_large(const std::string& structure, const std::string& option, const std::string& what,
                            std::uint64_t bytes, std::size_t limit) {
  throw Error(structure + (option.empty() ? "" : ": " + option) + ": " + what + " need " + std::to_string(bytes) +
              " bytes, more than the device's largest buffer (" + std::to_string(limit) +
              " bytes, CL_DEVICE_MAX_MEM_ALLOC_SIZE)");
}

struct Flattener {
  const KdPrimitives& prims;
  KdTree& tree;
  std::vector<const KdBuildNode*> leaves;  // by node index; null for inner nodes

  void emit(const KdBuildNode& node, std::uint32_t depth) {
    tree.depth = std::max(tree.depth, depth);
    std::size_t index = tree.nodes.size();
    tree.nodes.push_back({});
    leaves.push_back(node.axis < 0 ? &node : nullptr);
    if (node.axis < 0) {
      // Triangles first, each kind ascending: prims are sorted indices and
      // every triangle index is below every sphere index.
      std::size_t first = tree.refs.size();
      for (std::uint32_t i : node.prims)
        tree.refs.push_back(i < prims.triangle_count ? static_cast<rtcl_i32>(i)
                                                     : ~static_cast<rtcl_i32>(i - prims.triangle_count));
      tree.nodes[index] = {RTCL_KD_LEAF_NODE(std::min(first, kMaxIndex - 1)),
                           static_cast<rtcl_u32>(node.prims.size())};
      ++tree.leaf_count;
      return;
    }
    if (depth + 1 > static_cast<std::uint32_t>(kKdMaxDepth)) {
      tree.depth = depth + 1;
      return;
    }
    emit(*node.below, depth + 1);
    std::size_t above = tree.nodes.size();
    emit(*node.above, depth + 1);
    tree.nodes[index] = {RTCL_KD_INNER(node.axis, std::min(above, kMaxIndex - 1)),
                         std::bit_cast<rtcl_u32>(node.split)};
  }
};

}  // namespace



std::size_t KdTree::bytes() const {
  return sizeof(KdHeader) + nodes.size() * sizeof(KdNode) + fused.size() * sizeof(Bvh8Node) +
         refs.size() * sizeof(rtcl_i32) +
         lanes.size() * sizeof(float) + lane_prims.size() * sizeof(rtcl_i32) +
         blocks.spheres.size() * sizeof(SphereBlock);
}

double KdTree::references_per_primitive() const {
  std::size_t stored = 0;
  for (const TriangleBlock& b : blocks.triangles)
    for (rtcl_i32 p : b.prim) stored += p >= 0;
  for (const SphereBlock& b : blocks.spheres)
    for (rtcl_i32 p : b.prim) stored += p >= 0;
  return stored ? static_cast<double>(refs.size()) / static_cast<double>(stored) : 0.0;
}

void KdPrimitives::bounds(std::uint32_t i, glm::dvec3* lower, glm::dvec3* upper) const {
  const Geometry& g = *geometry;
  if (i < triangle_count) {
    const glm::uvec3& t = g.triangles[ids[i]];
    glm::dvec3 a(g.vertices[t.x]), b(g.vertices[t.y]), c(g.vertices[t.z]);
    *lower = glm::min(a, glm::min(b, c));
    *upper = glm::max(a, glm::max(b, c));
    return;
  }
  const Sphere& s = g.spheres[i - triangle_count];
  *lower = glm::dvec3(s.center) - static_cast<double>(s.radius);
  *upper = glm::dvec3(s.center) + static_cast<double>(s.radius);
}

bool KdPrimitives::clip(std::uint32_t i, const glm::dvec3& box_lower, const glm::dvec3& box_upper,
                        glm::dvec3* clipped_lower, glm::dvec3* clipped_upper) const {
  glm::dvec3 lo = box_lower - widen, hi = box_upper + widen;
  if (i < triangle_count) {
    const Geometry& g = *geometry;
    const glm::uvec3& t = g.triangles[ids[i]];
    return clip_triangle_bounds(glm::dvec3(g.vertices[t.x]), glm::dvec3(g.vertices[t.y]),
                                glm::dvec3(g.vertices[t.z]), lo, hi, clipped_lower, clipped_upper);
  }
  glm::dvec3 bl, bu;
  bounds(i, &bl, &bu);
  *clipped_lower = glm::max(bl, lo);
  *clipped_upper = glm::min(bu, hi);
  for (int a = 0; a < 3; ++a)
    if ((*clipped_lower)[a] > (*clipped_upper)[a]) return false;
  return true;
}

void KdPrimitives::clip_split(std::uint32_t i, const glm::dvec3& box_lower, const glm::dvec3& box_upper, int axis,
                              double p, std::array<bool, 2>* reaches, std::array<glm::dvec3, 2>* clipped_lower,
                              std::array<glm::dvec3, 2>* clipped_upper) const {
  if (i >= triangle_count) {
    glm::dvec3 below_upper = box_upper, above_lower = box_lower;
    below_upper[axis] = p;
    above_lower[axis] = p;
    (*reaches)[0] = clip(i, box_lower, below_upper, &(*clipped_lower)[0], &(*clipped_upper)[0]);
    (*reaches)[1] = clip(i, above_lower, box_upper, &(*clipped_lower)[1], &(*clipped_upper)[1]);
    return;
  }
  const Geometry& g = *geometry;
  const glm::uvec3& t = g.triangles[ids[i]];
  ClipSplit c = clip_triangle_split(glm::dvec3(g.vertices[t.x]), glm::dvec3(g.vertices[t.y]),
                                    glm::dvec3(g.vertices[t.z]), box_lower - widen, box_upper + widen, axis,
                                    p + widen, p - widen);
  *reaches = {c.below, c.above};
  *clipped_lower = {c.below_lower, c.above_lower};
  *clipped_upper = {c.below_upper, c.above_upper};
}

KdPrimitives kd_primitives(const Geometry& geometry, const std::string& structure, std::size_t max_alloc_bytes) {
  KdPrimitives p;
  p.geometry = &geometry;
  p.ids = stored_primitives(geometry);
  p.triangle_count = p.ids.size() - geometry.spheres.size();
  if (p.ids.size() >= kMaxIndex)
    throw Error(structure + " over " + geometry.source + ": " + std::to_string(p.ids.size()) +
                " primitives, more than the 2^30 a node can index");
  std::uint64_t block_bytes = ((p.triangle_count + 7) / 8) * sizeof(TriangleBlock);
  if (max_alloc_bytes && block_bytes > max_alloc_bytes)
    too_large(structure + " over " + geometry.source, "", "triangle blocks", block_bytes, max_alloc_bytes);
  Aabb box = geometry.bounds();
  glm::dvec3 lower(box.lower), upper(box.upper);
  double magnitude = 0.0;
  for (int a = 0; a < 3; ++a) magnitude = std::max({magnitude, std::fabs(lower[a]), std::fabs(upper[a])});
  double pad = std::max(16.0 * FLT_EPSILON * magnitude, static_cast<double>(FLT_MIN));
  p.widen = 64.0 * FLT_EPSILON * magnitude + static_cast<double>(FLT_MIN);
  for (int a = 0; a < 3; ++a) {
    p.lower[a] = kd_round_float(lower[a] - pad, true);
    p.upper[a] = kd_round_float(upper[a] + pad, false);
  }
  return p;
}

KdTree flatten_kd_tree(const KdPrimitives& prims, const KdBuildNode& root, const std::string& structure,
                       const std::string& option, std::size_t max_alloc_bytes, unsigned threads) {
  KdTree tree;
  for (int a = 0; a < 3; ++a) {
    tree.header.lower[a] = static_cast<float>(prims.lower[a]);
    tree.header.upper[a] = static_cast<float>(prims.upper[a]);
  }
  Flattener flattener{prims, tree, {}};
  flattener.emit(root, 0);
  std::string what = structure + " over " + prims.geometry->source;
  if (tree.depth > static_cast<std::uint32_t>(kKdMaxDepth))
    throw Error(what + ": " + option + ": the tree is deeper than the traversal stack's " +
                std::to_string(kKdMaxDepth) + " levels");
  if (tree.nodes.size() >= kMaxIndex || tree.refs.size() >= kMaxIndex)
    throw Error(what + ": " + option + ": " + std::to_string(tree.nodes.size()) + " nodes and " +
                std::to_string(tree.refs.size()) + " references, more than the 2^30 a node can index");
  if (max_alloc_bytes && tree.nodes.size() * sizeof(KdNode) > max_alloc_bytes)
    too_large(what, option, std::to_string(tree.nodes.size()) + " nodes", tree.nodes.size() * sizeof(KdNode),
              max_alloc_bytes);
  // A leaf's cell box shrunk to what its primitives clipped to the
  // (widened) cell cover, rounded outwards.
  auto fuse = [&] { tree.fused = fuse_kd_nodes(tree.nodes, tree.header, [&](std::size_t leaf, const KdBox& cell) {
    if (flattener.leaves[leaf]->has_content) return flattener.leaves[leaf]->content;
    KdBox tight = KdBox::empty();
    glm::dvec3 lo(cell.lower[0], cell.lower[1], cell.lower[2]), hi(cell.upper[0], cell.upper[1], cell.upper[2]);
    const std::uint32_t first = tree.nodes[leaf].flags >> 2, count = tree.nodes[leaf].data;
    for (std::uint32_t k = first; k < first + count; ++k) {
      const rtcl_i32 r = tree.refs[k];
      const std::uint32_t i = r >= 0 ? static_cast<std::uint32_t>(r)
                                     : static_cast<std::uint32_t>(prims.triangle_count) + static_cast<std::uint32_t>(~r);
      glm::dvec3 cl, cu;
      if (!prims.clip(i, lo, hi, &cl, &cu)) continue;
      for (int a = 0; a < 3; ++a) {
        tight.lower[a] = std::min(tight.lower[a], kd_round_float(cl[a], true));
        tight.upper[a] = std::max(tight.upper[a], kd_round_float(cu[a], false));
      }
    }
    return tight;
  }); };
  // The fused nodes on a second thread while this one fills the reference
  // lanes (neither writes what the other reads).
  std::jthread fuser;
  if (threads > 1) fuser = std::jthread(fuse);
  else fuse();
  if (max_alloc_bytes && tree.refs.size() * sizeof(rtcl_i32) > max_alloc_bytes)
    too_large(what, option, std::to_string(tree.refs.size()) + " references", tree.refs.size() * sizeof(rtcl_i32),
              max_alloc_bytes);
  const std::size_t stride = tree.refs.size() + kLanePadding;
  // The kernel indexes a lane row as row * lane_stride in int.
  if (9 * stride > static_cast<std::size_t>(std::numeric_limits<rtcl_i32>::max()))
    throw Error(what + ": " + option + ": " + std::to_string(tree.refs.size()) +
                " references, more than the reference lanes' 32-bit indices hold");
  if (max_alloc_bytes && 9 * stride * sizeof(float) > max_alloc_bytes)
    too_large(what, option, std::to_string(tree.refs.size()) + " reference lanes", 9 * stride * sizeof(float),
              max_alloc_bytes);
  tree.blocks = in_order_blocks(*prims.geometry, prims.ids);
  tree.header.lane_stride = static_cast<rtcl_i32>(stride);
  tree.lanes.assign(9 * stride, std::numeric_limits<float>::quiet_NaN());
  tree.lane_prims.assign(stride, -1);
  for (std::size_t k = 0; k < tree.refs.size(); ++k) {
    rtcl_i32 r = tree.refs[k];
    if (r < 0) continue;
    const TriangleBlock& b = tree.blocks.triangles[static_cast<std::size_t>(r) >> 3];
    for (int v = 0; v < 3; ++v)
      for (int a = 0; a < 3; ++a) tree.lanes[(3 * v + a) * stride + k] = b.v[v][a][r & 7];
    tree.lane_prims[k] = b.prim[r & 7];
  }
  if (fuser.joinable()) fuser.join();
  if (max_alloc_bytes && tree.fused.size() * sizeof(Bvh8Node) > max_alloc_bytes)
    too_large(what, option, std::to_string(tree.fused.size()) + " fused nodes",
              tree.fused.size() * sizeof(Bvh8Node), max_alloc_bytes);
  return tree;
}

bool KdThreads::try_take() {
  int spare = spare_.load();
  while (spare > 0)
    if (spare_.compare_exchange_weak(spare, spare - 1)) return true;
  return false;
}

namespace {

class KdAccel final : public Accel {
  static inline const TraceKernels kPacket{"accel/kdtree_packet.cl", 8};

 public:
  KdAccel(const Device& device, const Geometry& geometry, const std::string& name, const KdTree& tree,
          AccelStats stats, const AccelConfig& config, KdTraversal traversal, std::uint32_t occluder_run)
      : Accel(device, name,
              traversal == KdTraversal::packet
                  ? kPacket
                  : TraceKernels{"accel/kdtree.cl", 1, occluder_run_for(occluder_run, device.info())},
              traversal == KdTraversal::by_coherence && packets_for_coherent_calls(device.info())
                  ? std::optional(kPacket)
                  : std::nullopt,
              defines(geometry),
              stats, config),
        header_(device.upload(&tree.header, sizeof tree.header, (name + " header").c_str())),
        nodes_(device.upload(tree.nodes.data(), tree.nodes.size() * sizeof(KdNode), (name + " nodes").c_str())),
        fused_(device.upload(tree.fused.data(), tree.fused.size() * sizeof(Bvh8Node), (name + " fused nodes").c_str())),
        refs_(tree.refs.empty() ? device.upload(&kNoRef, sizeof kNoRef, (name + " references").c_str())
                                : device.upload(tree.refs.data(), tree.refs.size() * sizeof(rtcl_i32),
                                                (name + " references").c_str())),
        lanes_(device.upload(tree.lanes.data(), tree.lanes.size() * sizeof(float),
                             (name + " reference lanes").c_str())),
        lane_prims_(device.upload(tree.lane_prims.data(), tree.lane_prims.size() * sizeof(rtcl_i32),
                                  (name + " reference lane ids").c_str())),
        primitives_(upload(device, PrimitiveBlocks{{}, tree.blocks.spheres})) {}

 private:
  static constexpr rtcl_i32 kNoRef = 0;

  static std::vector<std::string> defines(const Geometry& geometry) {
    std::vector<std::string> d = primitive_defines(geometry);
    d.push_back("RTCL_KD_STACK=" + std::to_string(kKdMaxDepth));
    d.push_back("RTCL_KD_CELL_STACK=" + std::to_string(kKdCellStack));
    return d;
  }

  void set_structure_args(cl::Kernel& kernel, cl_uint first) const override {
    kernel.setArg(first, header_);
    kernel.setArg(first + 1, nodes_);
    kernel.setArg(first + 2, fused_);
    kernel.setArg(first + 3, refs_);
    kernel.setArg(first + 4, lanes_);
    kernel.setArg(first + 5, lane_prims_);
    kernel.setArg(first + 6, primitives_.spheres);
  }

  cl::Buffer header_, nodes_, fused_, refs_, lanes_, lane_prims_;
  DevicePrimitives primitives_;
};

}  // namespace

std::unique_ptr<Accel> make_kd_accel(const Device& device, const Geometry& geometry, const std::string& name,
                                     const KdTree& tree, AccelStats stats, const AccelConfig& config,
                                     KdTraversal traversal, std::uint32_t occluder_run) {
  return std::make_unique<KdAccel>(device, geometry, name, tree, stats, config, traversal, occluder_run);
}

}  // namespace rtcl

namespace rtcl {

std::unique_ptr<Accel> build_kd_accel(const Device& device, const Geometry& geometry, const std::string& name,
                                      const std::function<KdTree(std::size_t max_alloc_bytes)>& build,
                                      const AccelConfig& config, KdTraversal traversal, std::uint32_t occluder_run) {
  auto start = std::chrono::steady_clock::now();
  GeometryReport report = validate(geometry);
  KdTree tree = build(device.info().max_alloc_bytes);
  AccelStats stats;
  stats.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  stats.device_bytes = tree.bytes();
  stats.primitive_count = geometry.primitive_count() - report.zero_area_triangles;
  stats.zero_area_skipped = report.zero_area_triangles;
  stats.bounds = geometry.bounds();
  stats.node_count = tree.nodes.size() - tree.leaf_count;
  stats.leaf_count = tree.leaf_count;
  return make_kd_accel(device, geometry, name, tree, stats, config, traversal, occluder_run);
}

}  // namespace rtcl
