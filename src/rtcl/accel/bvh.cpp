#include "rtcl/accel/bvh.hpp"

#include <algorithm>
#include <array>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <limits>

#include "rtcl/error.hpp"

namespace rtcl {

namespace {

// A sphere's box, widened by a few ulps of its coordinates: centre +- radius
// rounded to float may fall just inside the true surface.
Aabb sphere_bounds(const Sphere& s) {
  float magnitude = std::max({std::fabs(s.center.x), std::fabs(s.center.y), std::fabs(s.center.z)}) + s.radius;
  glm::vec3 r(s.radius + 4.0f * FLT_EPSILON * magnitude);
  return {s.center - r, s.center + r};
}

BuildTree build_kind(std::span<const Aabb> bounds, std::span<const std::uint32_t> ids, const BvhConfig& config) {
  return config.builder == BvhBuilder::ploc ? build_ploc(bounds, ids, config.ploc) : build_sah(bounds, ids, config.sah);
}

bool contains(const Aabb& outer, const Aabb& inner) {
  return glm::all(glm::lessThanEqual(outer.lower, inner.lower)) &&
         glm::all(glm::greaterThanEqual(outer.upper, inner.upper));
}

// One child of a wide node while it is formed: an inner binary node, or a
// group of binary leaves that will share one block.
struct Slot {
  Aabb bounds;
  std::uint32_t node = 0;  // inner binary node (when !leaf)
  bool leaf = false;
  bool spheres = false;
  std::uint32_t count = 0;  // primitives (leaf groups)
  std::array<std::uint32_t, RTCL_BLOCK_WIDTH> leaves{};  // binary leaves in the group
  std::uint32_t leaf_count = 0;
};

class Flattener {
 public:
  Flattener(const BuildTree& tree, const Geometry& geometry, bool merge_leaves)
      : tree_(tree), geometry_(geometry), merge_leaves_(merge_leaves), node_seen_(tree.nodes.size(), 0),
        prim_seen_(geometry.primitive_count(), 0) {}

  Bvh8 run() {
    if (tree_.empty()) fail("the build tree is empty");
    struct Todo {
      std::uint32_t binary, wide, stack, depth;  // stack: entries its ancestors leave on the stack, worst case
    };
    out_.nodes.emplace_back();
    std::vector<Todo> todo{{0, 0, 0, 1}};
    visit(0);
    while (!todo.empty()) {
      Todo t = todo.back();
      todo.pop_back();
      std::vector<Slot> slots = form_slots(t.binary);
      // The kernel pushes the children it enters and pops the one it visits
      // next (kernels/accel/bvh.cl): entries peak at t.stack + children.
      auto children = static_cast<std::uint32_t>(slots.size());
      out_.stack_size = std::max(out_.stack_size, t.stack + children);
      std::uint32_t below = t.stack + children - 1;  // left for each child's subtree
      out_.depth = std::max(out_.depth, t.depth);
      if (out_.stack_size > kBvhMaxStackSize)
        throw Error("BVH over " + geometry_.source + ": the tree needs a traversal stack of more than " +
                    std::to_string(kBvhMaxStackSize) + " entries (depth " + std::to_string(t.depth) +
                    "); lower SahConfig::max_sah_depth or PlocConfig::max_depth");
      Bvh8Node node;
      for (int row = 0; row < 6; ++row)
        for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane)
          node.bounds[row][lane] = row < 3 ? std::numeric_limits<float>::infinity()
                                           : -std::numeric_limits<float>::infinity();
      for (int& c : node.child) c = RTCL_CHILD_EMPTY;
      std::size_t first_todo = todo.size();
      for (std::size_t lane = 0; lane < slots.size(); ++lane) {
        const Slot& s = slots[lane];
        for (int a = 0; a < 3; ++a) {
          node.bounds[a][lane] = s.bounds.lower[a];
          node.bounds[3 + a][lane] = s.bounds.upper[a];
        }
        if (s.leaf) {
          node.child[lane] = emit_block(s);
        } else {
          auto index = static_cast<std::uint32_t>(out_.nodes.size());
          if (index > 0x7ffffffeu) fail("too many nodes");
          out_.nodes.emplace_back();
          node.child[lane] = static_cast<rtcl_i32>(index);
          todo.push_back({s.node, index, below, t.depth + 1});
        }
      }
      std::reverse(todo.begin() + static_cast<std::ptrdiff_t>(first_todo), todo.end());
      out_.nodes[t.wide] = node;
    }
    for (std::size_t p = 0; p < prim_seen_.size(); ++p) {
      bool stored = p >= geometry_.triangles.size() || !zero_area(geometry_, p);
      if (stored && !prim_seen_[p]) fail("primitive " + std::to_string(p) + " is in no leaf");
      if (!stored && prim_seen_[p]) fail("zero-area triangle " + std::to_string(p) + " is in a leaf");
    }
    return std::move(out_);
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw Error("internal: BVH over " + geometry_.source + ": " + what);
  }

  void visit(std::uint32_t n) {
    if (n >= tree_.nodes.size()) fail("child " + std::to_string(n) + " does not exist");
    if (node_seen_[n]++) fail("node " + std::to_string(n) + " is reached twice");
  }

  Slot slot_of(std::uint32_t n) {
    const BuildNode& b = tree_.nodes[n];
    Slot s;
    s.bounds = b.bounds;
    s.node = n;
    if (!b.is_leaf()) return s;
    if (b.count > RTCL_BLOCK_WIDTH || std::size_t(b.first) + b.count > tree_.prims.size())
      fail("leaf " + std::to_string(n) + " has " + std::to_string(b.count) + " primitives from " +
           std::to_string(b.first));
    s.leaf = true;
    s.count = b.count;
    s.leaves[0] = n;
    s.leaf_count = 1;
    s.spheres = tree_.prims[b.first] >= geometry_.triangles.size();
    for (std::uint32_t k = b.first; k < b.first + b.count; ++k) {
      std::uint32_t p = tree_.prims[k];
      if (p >= geometry_.primitive_count()) fail("leaf " + std::to_string(n) + " holds unknown id " + std::to_string(p));
      if ((p >= geometry_.triangles.size()) != s.spheres) fail("leaf " + std::to_string(n) + " mixes kinds");
      if (!contains(b.bounds, geometry_.primitive_bounds(p)))
        fail("leaf " + std::to_string(n) + " does not contain primitive " + std::to_string(p));
    }
    return s;
  }

  // The children of the wide node made from binary node n.
  std::vector<Slot> form_slots(std::uint32_t n) {
    std::vector<Slot> slots;
    if (tree_.nodes[n].is_leaf()) {
      slots.push_back(slot_of(n));
      return slots;
    }
    open(n, slots);
    for (;;) {
      while (slots.size() < RTCL_BLOCK_WIDTH) {
        int widest = -1;
        for (std::size_t i = 0; i < slots.size(); ++i)
          if (!slots[i].leaf && (widest < 0 || slots[i].bounds.area() > slots[widest].bounds.area()))
            widest = static_cast<int>(i);
        if (widest < 0) break;
        std::uint32_t inner = slots[widest].node;
        slots.erase(slots.begin() + widest);
        open(inner, slots);
      }
      bool merged = merge_leaves_ && merge_one_pair(slots);
      bool can_open = std::any_of(slots.begin(), slots.end(), [](const Slot& s) { return !s.leaf; });
      if (!merged || !can_open) {
        while (merge_leaves_ && merge_one_pair(slots)) {
        }
        break;
      }
    }
    return slots;
  }

  // Appends the two children of inner binary node n, checked: each exists,
  // is reached once and lies inside n's box.
  void open(std::uint32_t n, std::vector<Slot>& slots) {
    const BuildNode& b = tree_.nodes[n];
    for (std::uint32_t c : b.child) {
      visit(c);
      if (!contains(b.bounds, tree_.nodes[c].bounds))
        fail("node " + std::to_string(n) + " does not contain its child " + std::to_string(c));
      slots.push_back(slot_of(c));
    }
  }

  // Merges the pair of leaf groups whose union saves the most area (SAH:
  // one block test on the union instead of one on each); false when none
  // fits in a block without raising the cost.
  static bool merge_one_pair(std::vector<Slot>& slots) {
    int best_i = -1, best_j = -1;
    float best_saving = -1.0f;
    for (std::size_t i = 0; i < slots.size(); ++i) {
      if (!slots[i].leaf) continue;
      for (std::size_t j = i + 1; j < slots.size(); ++j) {
        const Slot &a = slots[i], &b = slots[j];
        if (!b.leaf || a.spheres != b.spheres || a.count + b.count > RTCL_BLOCK_WIDTH) continue;
        float saving = a.bounds.area() + b.bounds.area() - merge(a.bounds, b.bounds).area();
        if (saving >= 0.0f && saving > best_saving) {
          best_saving = saving;
          best_i = static_cast<int>(i);
          best_j = static_cast<int>(j);
        }
      }
    }
    if (best_i < 0) return false;
    Slot& a = slots[best_i];
    const Slot& b = slots[best_j];
    a.bounds = merge(a.bounds, b.bounds);
    a.count += b.count;
    for (std::uint32_t k = 0; k < b.leaf_count; ++k) a.leaves[a.leaf_count++] = b.leaves[k];
    slots.erase(slots.begin() + best_j);
    return true;
  }

  rtcl_i32 emit_block(const Slot& s) {
    std::array<std::uint32_t, RTCL_BLOCK_WIDTH> prims{};
    std::uint32_t n = 0;
    for (std::uint32_t k = 0; k < s.leaf_count; ++k) {
      const BuildNode& b = tree_.nodes[s.leaves[k]];
      for (std::uint32_t i = b.first; i < b.first + b.count; ++i) {
        std::uint32_t p = tree_.prims[i];
        if (prim_seen_[p]++) fail("primitive " + std::to_string(p) + " is in two leaves");
        prims[n++] = p;
      }
    }
    return out_.blocks.append(geometry_, std::span(prims.data(), n));
  }

  const BuildTree& tree_;
  const Geometry& geometry_;
  bool merge_leaves_;
  std::vector<char> node_seen_, prim_seen_;
  Bvh8 out_;
};

class BvhAccel final : public Accel {
  static inline const TraceKernels kPacket{"accel/bvh_packet.cl", RTCL_BLOCK_WIDTH};

 public:
  BvhAccel(const Device& device, std::string name, BvhTraversal traversal, std::vector<std::string> defines,
           const Bvh8& bvh, AccelStats stats, const AccelConfig& config)
      : Accel(device, std::move(name),
              traversal == BvhTraversal::packet ? kPacket : TraceKernels{"accel/bvh.cl"},
              traversal == BvhTraversal::packet ? std::nullopt : std::optional(kPacket), std::move(defines), stats,
              config),
        nodes_(device.upload(bvh.nodes.data(), bvh.nodes.size() * sizeof(Bvh8Node), "BVH nodes")),
        primitives_(upload(device, bvh.blocks)) {}

 private:
  void set_structure_args(cl::Kernel& kernel, cl_uint first) const override {
    kernel.setArg(first, nodes_);
    kernel.setArg(first + 1, primitives_.triangles);
    kernel.setArg(first + 2, primitives_.spheres);
  }

  cl::Buffer nodes_;
  DevicePrimitives primitives_;
};

}  // namespace

BuildTree build_binary_bvh(const Geometry& geometry, const BvhConfig& config) {
  std::vector<std::uint32_t> ids = stored_primitives(geometry);
  auto first_sphere = static_cast<std::size_t>(
      std::partition_point(ids.begin(), ids.end(), [&](std::uint32_t p) { return p < geometry.triangles.size(); }) -
      ids.begin());
  std::vector<Aabb> bounds(ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i)
    bounds[i] = i < first_sphere ? geometry.primitive_bounds(ids[i])
                                 : sphere_bounds(geometry.spheres[ids[i] - geometry.triangles.size()]);
  std::span<const Aabb> all_bounds(bounds);
  std::span<const std::uint32_t> all_ids(ids);
  return join(build_kind(all_bounds.first(first_sphere), all_ids.first(first_sphere), config),
              build_kind(all_bounds.subspan(first_sphere), all_ids.subspan(first_sphere), config));
}

Bvh8 flatten_bvh8(const BuildTree& tree, const Geometry& geometry, bool merge_leaves) {
  return Flattener(tree, geometry, merge_leaves).run();
}

std::uint32_t bvh_kernel_stack_size(std::uint32_t stack_size) { return std::max(8u, (stack_size + 7u) / 8u * 8u); }

AccelStats bvh_stats(const Geometry& geometry, const GeometryReport& report, const Bvh8& bvh,
                     std::chrono::steady_clock::time_point start) {
  AccelStats stats;
  stats.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  stats.device_bytes = bvh.nodes.size() * sizeof(Bvh8Node) + bvh.blocks.bytes();
  stats.primitive_count = geometry.primitive_count() - report.zero_area_triangles;
  stats.zero_area_skipped = report.zero_area_triangles;
  stats.node_count = bvh.nodes.size();
  stats.leaf_count = bvh.blocks.triangles.size() + bvh.blocks.spheres.size();
  return stats;
}

std::vector<std::string> bvh_defines(const Geometry& geometry, const Bvh8& bvh) {
  std::vector<std::string> defines = primitive_defines(geometry);
  defines.push_back("RTCL_STACK_SIZE=" + std::to_string(bvh_kernel_stack_size(bvh.stack_size)));
  return defines;
}

std::unique_ptr<Accel> make_bvh(const Device& device, const Geometry& geometry, const BvhConfig& config,
                                std::string name, const AccelConfig& accel_config) {
  auto start = std::chrono::steady_clock::now();
  GeometryReport report = validate(geometry);
  Bvh8 bvh = flatten_bvh8(build_binary_bvh(geometry, config), geometry, config.merge_leaves);
  AccelStats stats = bvh_stats(geometry, report, bvh, start);
  std::vector<std::string> defines = bvh_defines(geometry, bvh);
  return std::make_unique<BvhAccel>(device, std::move(name), config.traversal, std::move(defines), bvh, stats,
                                    accel_config);
}

namespace {

OptionSpec merge_leaves_option() {
  return {"merge_leaves", OptionType::boolean, true, 0, 0, false,
          "two leaves of a wide node share a block when they fit in 8 lanes and the SAH allows: fewer block "
          "tests and bytes; rarely applies to SAH trees"};
}
OptionSpec node_cost_option() {
  return {"node_cost", OptionType::real, 0.5, 0, 64, true,
          "cost of entering a binary node relative to one 8-primitive block test: higher gives shallower trees "
          "with fuller leaves, lower splits more eagerly"};
}
OptionSpec max_leaf_size_option() {
  return {"max_leaf_size", OptionType::integer, std::int64_t{8}, 1, 8, false,
          "largest leaf; leaves tend to fill the 8 lanes, a smaller cap only adds nodes"};
}

const std::vector<OptionSpec>& sah_options() {
  static const std::vector<OptionSpec> options = {
      {"bin_count", OptionType::integer, std::int64_t{32}, 2, 256, false,
       "SAH bins per axis: more find better planes where density is uneven (sponza primary rays +18% from 16 to "
       "32), at ~10% more build time"},
      node_cost_option(),
      max_leaf_size_option(),
      {"max_sah_depth", OptionType::integer, std::int64_t{48}, 1, 1024, false,
       "deeper nodes split at the object median: bounds the depth and traversal stack, at some quality loss"},
      merge_leaves_option(),
  };
  return options;
}

BvhConfig bvh_config(const StructureSpec& structure, const AccelConfig& config) {
  AccelOptions o = resolve_options(structure, config.options, "--accel " + structure.name);
  BvhConfig bvh;
  bvh.merge_leaves = o.boolean("merge_leaves");
  if (o.has("bin_count")) {
    bvh.sah.bin_count = static_cast<std::uint32_t>(o.integer("bin_count"));
    bvh.sah.node_cost = static_cast<float>(o.real("node_cost"));
    bvh.sah.max_leaf_size = static_cast<std::uint32_t>(o.integer("max_leaf_size"));
    bvh.sah.max_sah_depth = static_cast<std::uint32_t>(o.integer("max_sah_depth"));
  } else {
    bvh.builder = BvhBuilder::ploc;
    bvh.ploc.search_radius = static_cast<std::uint32_t>(o.integer("search_radius"));
    bvh.ploc.node_cost = static_cast<float>(o.real("node_cost"));
    bvh.ploc.max_leaf_size = static_cast<std::uint32_t>(o.integer("max_leaf_size"));
    bvh.ploc.max_depth = static_cast<std::uint32_t>(o.integer("max_depth"));
  }
  return bvh;
}

}  // namespace

const std::vector<OptionSpec>& bvh_sah_options() { return sah_options(); }

BvhConfig resolve_bvh_config(const StructureSpec& structure, const AccelConfig& config) {
  return bvh_config(structure, config);
}

const StructureSpec& bvh_structure() {
  static const StructureSpec spec{"bvh", "8-wide BVH, top-down binned SAH; packets of 8 rays for coherent calls",
                                  sah_options()};
  return spec;
}

const StructureSpec& bvh_ploc_structure() {
  static const StructureSpec spec{
      "bvh-ploc", "8-wide BVH, bottom-up agglomerative clustering (PLOC)",
      {{"search_radius", OptionType::integer, std::int64_t{16}, 1, 1024, false,
        "clusters searched on each side in Morton order: larger finds closer partners (bunny: r=4 / 64 trace 7% "
        "slower / 3% faster than 16) at a build cost linear in r"},
       node_cost_option(),
       max_leaf_size_option(),
       {"max_depth", OptionType::integer, std::int64_t{64}, 1, 1024, false,
        "subtrees reaching this depth are rebuilt by median splits: bounds the stack for chain-forming inputs"},
       merge_leaves_option()}};
  return spec;
}

const StructureSpec& bvh_packet_structure() {
  static const StructureSpec spec{"bvh-packet", "the bvh, always traced in packets of 8 rays (for measuring)",
                                  sah_options()};
  return spec;
}

std::unique_ptr<Accel> make_bvh_sah(const Device& device, const Geometry& geometry, const AccelConfig& config) {
  return make_bvh(device, geometry, bvh_config(bvh_structure(), config), "bvh", config);
}

std::unique_ptr<Accel> make_bvh_ploc(const Device& device, const Geometry& geometry, const AccelConfig& config) {
  return make_bvh(device, geometry, bvh_config(bvh_ploc_structure(), config), "bvh-ploc", config);
}

std::unique_ptr<Accel> make_bvh_packet(const Device& device, const Geometry& geometry, const AccelConfig& config) {
  BvhConfig bvh = bvh_config(bvh_packet_structure(), config);
  bvh.traversal = BvhTraversal::packet;
  return make_bvh(device, geometry, bvh, "bvh-packet", config);
}

}  // namespace rtcl
