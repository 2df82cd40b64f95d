// flatten_bvh8 (bvh.hpp): the binary build tree collapsed into 8-wide nodes
// and primitive blocks, in three passes.
//
// 1. Walk: wide nodes are formed depth first: those of the top greedy_levels
//    wide levels by opening the child of largest area until eight, those below
//    by the SAH-optimal plan (bvh_collapse.hpp). A wide node's inner children
//    get consecutive indices when it is formed, and the first child's subtree
//    is formed before the second's; blocks are numbered in the order their wide
//    nodes are formed. A block is recorded as its lanes' primitive ids and
//    binary leaves; the walk reads the tree, never the geometry. Trees of
//    kSplitMinNodes binary nodes and more are walked in parts: the top
//    kSplitDepth - 1 wide levels first, then each subtree below them on
//    whichever thread is free, each part's nodes and blocks placed after the
//    top's in the order the top met them, so that the result does not depend on
//    the threads. When the top levels are greedy (the default), each part
//    plans its own subtree before walking it; otherwise the whole tree is
//    planned first.
// 2. Gather (block ranges on parallel threads): each block is filled from the
//    geometry, every primitive's vertices read once and checked there: inside
//    its binary leaf's box, not a zero-area triangle, not marked before by
//    the same thread.
// 3. Marks: no primitive marked by two threads, and every stored primitive
//    marked; the unmarked (zero-area) triangles are listed.
#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <limits>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "rtcl/accel/bvh.hpp"
#include "rtcl/accel/bvh_collapse.hpp"
#include "rtcl/error.hpp"
#include "rtcl/huge_pages.hpp"
#include "rtcl/parallel.hpp"

namespace rtcl {

namespace {

// One child of a wide node while it is formed: an inner binary node, or a
// group of binary leaves that will share one block.
struct Slot {
  Aabb bounds;
  std::uint32_t node = 0;  // inner binary node (when !leaf)
  bool leaf = false;
  bool spheres = false;
  std::uint32_t count = 0;  // primitives (leaf groups)
  std::array<std::uint32_t, RTCL_BLOCK_WIDTH> leaves{};  // binary leaves in the group, in lane order
  std::uint32_t leaf_count = 0;
};

// The children of one wide node while it is formed, in lane order. At most
// RTCL_BLOCK_WIDTH: a slot is opened (replaced by two) only below that.
class SlotList {
 public:
  std::size_t size() const { return size_; }
  Slot& operator[](std::size_t i) { return items_[i]; }
  const Slot& operator[](std::size_t i) const { return items_[i]; }
  const Slot* begin() const { return items_.data(); }
  const Slot* end() const { return items_.data() + size_; }

  void push_back(const Slot& s) {
    if (size_ == items_.size()) throw Error("internal: BVH flatten: more than 8 children in a wide node");
    items_[size_++] = s;
  }
  void erase(std::size_t i) {
    std::copy(items_.begin() + static_cast<std::ptrdiff_t>(i) + 1,
              items_.begin() + static_cast<std::ptrdiff_t>(size_), items_.begin() + static_cast<std::ptrdiff_t>(i));
    --size_;
  }

 private:
  std::array<Slot, RTCL_BLOCK_WIDTH> items_{};
  std::size_t size_ = 0;
};

// What fills one block: each lane's primitive and the binary leaf that held
// it (whose box must contain it).
struct BlockSource {
  std::array<std::uint32_t, RTCL_BLOCK_WIDTH> prims;
  std::array<std::uint32_t, RTCL_BLOCK_WIDTH> leaves;
  std::uint32_t count;  // lanes in use
};

// What one walk forms: wide nodes (children indexed within them, blocks
// within its sources) and the blocks' sources.
struct WalkOutput {
  std::vector<Bvh8Node> nodes;
  std::vector<BlockSource> triangle_sources, sphere_sources;
  std::uint32_t stack_size = 0, depth = 0;
};

// The sources of one kind's blocks, in block order, left in the walks'
// outputs (the top's, then each part's) rather than copied into one array.
class BlockSources {
 public:
  void append(const std::vector<BlockSource>& run) {
    if (run.empty()) return;
    runs_.push_back({&run, size_});
    size_ += run.size();
  }
  std::size_t size() const { return size_; }
  // fn(sources, first): for each run that overlaps blocks [begin, end), in
  // order, its part there; sources[i] fills block first + i.
  template <class Fn>
  void for_each_run(std::size_t begin, std::size_t end, Fn&& fn) const {
    for (const Run& run : runs_) {
      const std::size_t from = std::max(begin, run.first), to = std::min(end, run.first + run.sources->size());
      if (from < to) fn(std::span<const BlockSource>(run.sources->data() + (from - run.first), to - from), from);
    }
  }

 private:
  struct Run {
    const std::vector<BlockSource>* sources;
    std::size_t first;  // the block sources[0] fills
  };
  std::vector<Run> runs_;
  std::size_t size_ = 0;
};

// A wide node to form from binary node `binary` at index `wide`; stack:
// the entries its ancestors leave on the traversal stack, worst case.
struct Todo {
  std::uint32_t binary, wide, stack, depth;
};

// A subtree the top walk leaves to a part: its first wide node and the
// lane of the top node that refers to it.
struct Deferred {
  Todo todo;
  std::uint32_t parent, lane;
};

// Trees walked in parts (see above), and the wide depth of the parts' roots
// (up to 64 parts).
constexpr std::size_t kSplitMinNodes = 4096;
constexpr std::uint32_t kSplitDepth = 3;

// Leaf reference `ref` of a part, its block moved by the offset of its kind.
rtcl_i32 rebase_leaf(rtcl_i32 ref, std::uint32_t triangle_offset, std::uint32_t sphere_offset) {
  const auto code = static_cast<std::uint32_t>(~ref);
  const std::uint32_t block = (code >> 1) + ((code & 1) ? sphere_offset : triangle_offset);
  return (code & 1) ? RTCL_LEAF_SPHERES(block) : RTCL_LEAF_TRIANGLES(block);
}

Bvh8Node empty_node() {
  Bvh8Node node;
  for (int row = 0; row < 6; ++row)
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane)
      node.bounds[row][lane] = row < 3 ? std::numeric_limits<float>::infinity()
                                       : -std::numeric_limits<float>::infinity();
  for (int& c : node.child) c = RTCL_CHILD_EMPTY;
  return node;
}

// Blocks below which the gather stays on one thread (a part's hand-off to
// another thread costs about as much as gathering a hundred blocks).
constexpr std::size_t kParallelMinBlocks = 512;
// How many blocks ahead of the one being filled the gather prefetches the
// triangles' index records and leaf boxes, and then their vertices: the
// reads are scattered over the geometry (leaf order), so each would
// otherwise wait for memory in turn. The distances are not critical: any
// few blocks ahead hide most of the latency.
constexpr std::size_t kIndexAhead = 16;
constexpr std::size_t kVertexAhead = 8;

// Starts loading the cache line at p (for writing when Write). The empty asm
// statement keeps loops whose only effect is prefetching: GCC 12 deletes them
// as side-effect free (-ffinite-loops, on from -O2 in C++11 and later).
template <int Write = 0>
inline void prefetch(const void* p) {
  __builtin_prefetch(p, Write);
  asm volatile("" ::"r"(p));
}

class Flattener {
 public:
  Flattener(const BuildTree& tree, const Geometry& geometry, const FlattenOptions& options)
      : tree_(tree),
        geometry_(geometry),
        merge_leaves_(options.merge_leaves),
        split_references_(options.split_references),
        greedy_levels_(options.greedy_levels),
        node_seen_(tree.nodes.size()) {
    threads_ = options.thread_count ? options.thread_count : std::max(1u, std::thread::hardware_concurrency());
  }

  Bvh8 run() {
    if (tree_.empty()) fail("the build tree is empty");
    walk();
    // what only the walk reads, freed before the gather's block array
    plan_ = CollapsePlan();
    std::vector<std::atomic<std::uint8_t>>().swap(node_seen_);
    gather();
    check_every_primitive_once();
    return std::move(out_);
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw Error("internal: BVH over " + geometry_.source + ": " + what);
  }

  // Pass 1: forms every wide node; blocks are recorded as sources.
  // The plan (bvh_collapse.hpp) is made where the walk needs it: the whole
  // tree's first, or, when the top's wide levels are all greedy, each
  // part's by the part, on the parts' threads (on one thread it is a
  // sizeable share of the flatten).
  void walk() {
    const Bvh8Node empty = empty_node();
    std::vector<Deferred> deferred;
    const bool in_parts = tree_.nodes.size() >= kSplitMinNodes;
    const bool plan_by_part = in_parts && greedy_levels_ + 1 >= kSplitDepth;
    plan_ = plan_by_part ? CollapsePlan(tree_.nodes.size()) : plan_collapse(tree_, geometry_);
    visit(0);
    walks_.resize(1);
    walks_[0].nodes.emplace_back();
    walk_from({0, 0, 0, 1}, walks_[0], in_parts ? &deferred : nullptr, empty);
    walks_.resize(1 + deferred.size());
    for_each_index(deferred.size(), threads_, [&](std::size_t k) {
      if (plan_by_part) plan_subtree(tree_, geometry_, deferred[k].todo.binary, plan_);
      WalkOutput& part = walks_[1 + k];
      part.nodes.emplace_back();
      walk_from(deferred[k].todo, part, nullptr, empty);
      // the sources stay until the gather: without the slack of their growth
      part.triangle_sources.shrink_to_fit();
      part.sphere_sources.shrink_to_fit();
    });
    assemble(deferred);
  }

  // Forms the wide nodes of the subtree from `root` (whose node out.nodes
  // holds, at root.wide) depth first. With `deferred`, the wide nodes of
  // depth kSplitDepth are left to parts: recorded there, their lanes'
  // children filled in by assemble.
  void walk_from(Todo root, WalkOutput& out, std::vector<Deferred>* deferred, const Bvh8Node& empty) {
    std::vector<Todo> todo{root};
    while (!todo.empty()) {
      Todo t = todo.back();
      todo.pop_back();
      SlotList slots = form_slots(t.binary, t.depth);
      // The kernel pushes the children it enters and pops the one it visits
      // next (kernels/accel/bvh.cl): entries peak at t.stack + children.
      auto children = static_cast<std::uint32_t>(slots.size());
      out.stack_size = std::max(out.stack_size, t.stack + children);
      std::uint32_t below = t.stack + children - 1;  // left for each child's subtree
      out.depth = std::max(out.depth, t.depth);
      if (out.stack_size > kBvhMaxStackSize)
        throw Error("BVH over " + geometry_.source + ": the tree needs a traversal stack of more than " +
                    std::to_string(kBvhMaxStackSize) + " entries (depth " + std::to_string(t.depth) +
                    "); lower SahConfig::max_sah_depth or PlocConfig::max_depth");
      Bvh8Node node = empty;
      std::size_t first_todo = todo.size();
      for (std::size_t lane = 0; lane < slots.size(); ++lane) {
        const Slot& s = slots[lane];
        for (int a = 0; a < 3; ++a) {
          node.bounds[a][lane] = s.bounds.lower[a];
          node.bounds[3 + a][lane] = s.bounds.upper[a];
        }
        if (s.leaf) {
          node.child[lane] = record_block(s, out, tree_, split_references_);
        } else if (deferred && t.depth + 1 == kSplitDepth) {
          deferred->push_back({{s.node, 0, below, t.depth + 1}, t.wide, static_cast<std::uint32_t>(lane)});
        } else {
          auto index = static_cast<std::uint32_t>(out.nodes.size());
          if (index > 0x7ffffffeu) fail("too many nodes");
          out.nodes.emplace_back();
          node.child[lane] = static_cast<rtcl_i32>(index);
          todo.push_back({s.node, index, below, t.depth + 1});
        }
      }
      std::reverse(todo.begin() + static_cast<std::ptrdiff_t>(first_todo), todo.end());
      out.nodes[t.wide] = node;
    }
  }

  // The top's and the parts' nodes in one array, the top's first, then
  // each part's in the order of `deferred` (walks_[1 + k] is part k), their
  // indices moved by what comes before them; parts are copied on
  // whichever thread is free. The blocks' sources stay where the walks put
  // them, in the same order.
  void assemble(const std::vector<Deferred>& deferred) {
    struct Offsets {
      std::size_t nodes, triangles, spheres;
    };
    std::vector<Offsets> offsets(walks_.size());
    Offsets end{0, 0, 0};
    for (std::size_t w = 0; w < walks_.size(); ++w) {
      offsets[w] = end;
      end.nodes += walks_[w].nodes.size();
      end.triangles += walks_[w].triangle_sources.size();
      end.spheres += walks_[w].sphere_sources.size();
      out_.stack_size = std::max(out_.stack_size, walks_[w].stack_size);
      out_.depth = std::max(out_.depth, walks_[w].depth);
      triangle_sources_.append(walks_[w].triangle_sources);
      sphere_sources_.append(walks_[w].sphere_sources);
    }
    if (end.nodes > 0x7fffffffu) fail("too many nodes");
    out_.nodes = std::move(walks_[0].nodes);
    reserve_faulted(out_.nodes, end.nodes, threads_);
    out_.nodes.resize(end.nodes);
    for (std::size_t k = 0; k < deferred.size(); ++k)
      out_.nodes[deferred[k].parent].child[deferred[k].lane] = static_cast<rtcl_i32>(offsets[1 + k].nodes);
    for_each_index(deferred.size(), threads_, [&](std::size_t k) {
      WalkOutput& part = walks_[1 + k];
      const Offsets& at = offsets[1 + k];
      const auto node_offset = static_cast<rtcl_i32>(at.nodes);
      const auto triangle_offset = static_cast<std::uint32_t>(at.triangles);
      const auto sphere_offset = static_cast<std::uint32_t>(at.spheres);
      Bvh8Node* to = out_.nodes.data() + at.nodes;
      for (Bvh8Node node : part.nodes) {
        for (rtcl_i32& c : node.child)
          if (c >= 0)
            c += node_offset;
          else if (c != RTCL_CHILD_EMPTY)
            c = rebase_leaf(c, triangle_offset, sphere_offset);
        *to++ = node;
      }
      std::vector<Bvh8Node>().swap(part.nodes);
    });
  }

  void visit(std::uint32_t n) {
    if (n >= tree_.nodes.size()) fail("child " + std::to_string(n) + " does not exist");
    if (node_seen_[n].exchange(1, std::memory_order_relaxed)) fail("node " + std::to_string(n) + " is reached twice");
  }

  // Binary node n as a slot. A leaf is checked against the tree alone (1..8
  // known ids of one kind); its primitives' boxes are checked by the gather.
  Slot slot_of(std::uint32_t n) const {
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
    }
    return s;
  }

  // The children of the wide node made from binary node n at wide depth
  // `depth` (the root's 1): greedy in the top greedy_levels_, else planned.
  SlotList form_slots(std::uint32_t n, std::uint32_t depth) {
    SlotList slots;
    const BuildNode& b = tree_.nodes[n];
    if (b.is_leaf()) {
      slots.push_back(slot_of(n));
      return slots;
    }
    if (depth > greedy_levels_) {
      check_children(n);
      const auto [left, right] = plan_.wide_split(n);
      distribute(b.child[0], left, slots);
      distribute(b.child[1], right, slots);
      while (merge_leaves_ && merge_one_pair(slots)) {
      }
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
        slots.erase(static_cast<std::size_t>(widest));
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

  // Checks the two children of inner binary node n: each exists, is
  // reached once and lies inside n's box.
  void check_children(std::uint32_t n) {
    const BuildNode& b = tree_.nodes[n];
    for (std::uint32_t c : b.child) {
      visit(c);
      if (!b.bounds.contains(tree_.nodes[c].bounds))
        fail("node " + std::to_string(n) + " does not contain its child " + std::to_string(c));
    }
  }

  // Appends the two children of inner binary node n, checked.
  void open(std::uint32_t n, SlotList& slots) {
    check_children(n);
    for (std::uint32_t c : tree_.nodes[n].child) slots.push_back(slot_of(c));
  }

  // Appends binary node m's subtree as at most `budget` slots, as planned.
  void distribute(std::uint32_t m, int budget, SlotList& slots) {
    const auto [left, right] = plan_.split(m, budget);
    const BuildNode& b = tree_.nodes[m];
    if (left > 0) {
      check_children(m);
      distribute(b.child[0], left, slots);
      distribute(b.child[1], right, slots);
    } else if (b.is_leaf() || !plan_.is_block(m)) {
      slots.push_back(slot_of(m));
    } else {
      Slot group;
      add_to_group(m, group);
      slots.push_back(group);
    }
  }

  // Adds the binary leaves of m's subtree (at most eight primitives, as
  // planned) to the leaf group `group`, checked.
  void add_to_group(std::uint32_t m, Slot& group) {
    const BuildNode& b = tree_.nodes[m];
    if (!b.is_leaf()) {
      check_children(m);
      add_to_group(b.child[0], group);
      add_to_group(b.child[1], group);
      return;
    }
    const Slot s = slot_of(m);
    if (group.leaf_count == 0) {
      group = s;
      return;
    }
    group.bounds = merge(group.bounds, s.bounds);
    group.count += s.count;
    group.leaves[group.leaf_count++] = m;
  }

  // Merges the pair of leaf groups whose union saves the most area (SAH:
  // one block test on the union instead of one on each); false when none
  // fits in a block without raising the cost.
  static bool merge_one_pair(SlotList& slots) {
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
    Slot& a = slots[static_cast<std::size_t>(best_i)];
    const Slot& b = slots[static_cast<std::size_t>(best_j)];
    a.bounds = merge(a.bounds, b.bounds);
    a.count += b.count;
    for (std::uint32_t k = 0; k < b.leaf_count; ++k) a.leaves[a.leaf_count++] = b.leaves[k];
    slots.erase(static_cast<std::size_t>(best_j));
    return true;
  }

  // The leaf reference of the next block of s's kind in out, filled by the
  // gather. With split references, two parts of one triangle in s's leaves
  // take one lane.
  static rtcl_i32 record_block(const Slot& s, WalkOutput& out, const BuildTree& tree, bool split_references) {
    BlockSource source;
    source.count = 0;
    for (std::uint32_t k = 0; k < s.leaf_count; ++k) {
      const BuildNode& leaf = tree.nodes[s.leaves[k]];
      for (std::uint32_t i = 0; i < leaf.count; ++i) {
        const std::uint32_t p = tree.prims[leaf.first + i];
        if (split_references && std::find(source.prims.begin(), source.prims.begin() + source.count, p) !=
                                    source.prims.begin() + source.count)
          continue;
        source.prims[source.count] = p;
        source.leaves[source.count++] = s.leaves[k];
      }
    }
    std::vector<BlockSource>& sources = s.spheres ? out.sphere_sources : out.triangle_sources;
    sources.push_back(source);
    auto block = sources.size() - 1;
    return s.spheres ? RTCL_LEAF_SPHERES(block) : RTCL_LEAF_TRIANGLES(block);
  }

  // Pass 2: fills every block, the blocks of each kind split evenly over
  // the threads; the first thread's error (in block order) is the one thrown.
  void gather() {
    reserve_advised(out_.blocks.triangles, triangle_sources_.size());
    out_.blocks.triangles.resize(triangle_sources_.size());
    out_.blocks.spheres.resize(sphere_sources_.size());
    std::size_t blocks = triangle_sources_.size() + sphere_sources_.size();
    unsigned parts = blocks < kParallelMinBlocks ? 1u : threads_;
    seen_.assign(parts, std::vector<std::uint64_t>(geometry_.primitive_count() / 64 + 1, 0));
    // part k: the k-th share of each kind's blocks, on its own thread
    for_each_part(parts, parts, [&](unsigned k, std::size_t, std::size_t) {
      triangle_sources_.for_each_run(triangle_sources_.size() * k / parts, triangle_sources_.size() * (k + 1) / parts,
                                     [&](std::span<const BlockSource> sources, std::size_t first) {
                                       gather_triangles(seen_[k], sources, first);
                                     });
      sphere_sources_.for_each_run(sphere_sources_.size() * k / parts, sphere_sources_.size() * (k + 1) / parts,
                                   [&](std::span<const BlockSource> sources, std::size_t first) {
                                     gather_spheres(seen_[k], sources, first);
                                   });
    });
  }

  // Blocks first, first + 1, ... from sources.
  void gather_triangles(std::vector<std::uint64_t>& seen, std::span<const BlockSource> sources, std::size_t first) {
    const std::size_t n = sources.size();
    for (std::size_t i = 0; i < std::min(n, kIndexAhead); ++i) prefetch_indices(sources[i]);
    for (std::size_t i = 0; i < std::min(n, kVertexAhead); ++i) prefetch_vertices(sources[i]);
    for (std::size_t i = 0; i < n; ++i) {
      if (i + kIndexAhead < n) prefetch_indices(sources[i + kIndexAhead]);
      if (i + kVertexAhead < n) prefetch_vertices(sources[i + kVertexAhead]);
      fill_triangle_block(seen, sources[i], first + i);
    }
  }

  // The block's triangle records and its leaves' boxes.
  void prefetch_indices(const BlockSource& source) const {
    for (std::uint32_t lane = 0; lane < source.count; ++lane) {
      prefetch(&geometry_.triangles[source.prims[lane]]);
      if (lane == 0 || source.leaves[lane] != source.leaves[lane - 1]) prefetch(&tree_.nodes[source.leaves[lane]]);
    }
  }

  void prefetch_vertices(const BlockSource& source) const {
    for (std::uint32_t lane = 0; lane < source.count; ++lane) {
      const glm::uvec3& t = geometry_.triangles[source.prims[lane]];
      for (int k = 0; k < 3; ++k) prefetch(&geometry_.vertices[t[k]]);
    }
  }

  void fill_triangle_block(std::vector<std::uint64_t>& seen, const BlockSource& source, std::size_t block) {
    TriangleBlock out = empty_triangle_block();
    for (std::uint32_t lane = 0; lane < source.count; ++lane) {
      std::uint32_t p = source.prims[lane];
      const glm::uvec3& t = geometry_.triangles[p];
      const glm::vec3 &a = geometry_.vertices[t.x], &b = geometry_.vertices[t.y], &c = geometry_.vertices[t.z];
      const Aabb& box = tree_.nodes[source.leaves[lane]].bounds;
      if (split_references_ ? !meets(box, a, b, c) : !box.contains(a) || !box.contains(b) || !box.contains(c))
        fail_outside(source.leaves[lane], p);
      if (zero_area(a, b, c)) fail("zero-area triangle " + std::to_string(p) + " is in a leaf");
      mark(seen, p, split_references_);
      set_lane(out, lane, p, a, b, c);
    }
    out_.blocks.triangles[block] = out;
  }

  void gather_spheres(std::vector<std::uint64_t>& seen, std::span<const BlockSource> sources, std::size_t first) {
    for (std::size_t i = 0; i < sources.size(); ++i) {
      const BlockSource& source = sources[i];
      SphereBlock out = empty_sphere_block();
      for (std::uint32_t lane = 0; lane < source.count; ++lane) {
        std::uint32_t p = source.prims[lane];
        if (!tree_.nodes[source.leaves[lane]].bounds.contains(geometry_.primitive_bounds(p)))
          fail_outside(source.leaves[lane], p);
        mark(seen, p, false);
        set_lane(out, lane, p, geometry_.spheres[p - geometry_.triangles.size()]);
      }
      out_.blocks.spheres[first + i] = out;
    }
  }

  [[noreturn]] void fail_outside(std::uint32_t leaf, std::uint32_t p) const {
    const char* relation = split_references_ ? " does not meet primitive " : " does not contain primitive ";
    fail("leaf " + std::to_string(leaf) + relation + std::to_string(p));
  }

  // Whether box and the box of triangle (a, b, c) share a point: a leaf
  // that holds a part of a split triangle (bvh_presplit.hpp) holds at least
  // that.
  static bool meets(const Aabb& box, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    const glm::vec3 lower = glm::min(a, glm::min(b, c)), upper = glm::max(a, glm::max(b, c));
    return glm::all(glm::lessThanEqual(box.lower, upper)) && glm::all(glm::lessThanEqual(lower, box.upper));
  }

  // Sets p's bit in one thread's marks; a second mark fails unless
  // `may_repeat`.
  void mark(std::vector<std::uint64_t>& seen, std::uint32_t p, bool may_repeat) const {
    std::uint64_t bit = std::uint64_t(1) << (p % 64);
    if ((seen[p / 64] & bit) && !may_repeat) fail("primitive " + std::to_string(p) + " is in two leaves");
    seen[p / 64] |= bit;
  }

  // Pass 3: no primitive marked by two threads (unless references are
  // split), and the unmarked ones are exactly the zero-area triangles.
  void check_every_primitive_once() {
    std::vector<std::uint64_t>& all = seen_[0];
    for (std::size_t k = 1; k < seen_.size(); ++k)
      for (std::size_t w = 0; w < all.size(); ++w) {
        if (std::uint64_t twice = split_references_ ? 0 : all[w] & seen_[k][w])
          fail("primitive " + std::to_string(64 * w + static_cast<std::size_t>(std::countr_zero(twice))) +
               " is in two leaves");
        all[w] |= seen_[k][w];
      }
    const std::size_t count = geometry_.primitive_count();
    for (std::size_t w = 0; w < all.size(); ++w)
      for (std::uint64_t missing = ~all[w]; missing; missing &= missing - 1) {
        std::size_t p = 64 * w + static_cast<std::size_t>(std::countr_zero(missing));
        if (p >= count) break;
        if (p >= geometry_.triangles.size() || !zero_area(geometry_, p))
          fail("primitive " + std::to_string(p) + " is in no leaf");
        out_.zero_area_triangles.push_back(static_cast<std::uint32_t>(p));
      }
  }

  const BuildTree& tree_;
  const Geometry& geometry_;
  bool merge_leaves_;
  bool split_references_;  // a triangle may sit in several leaves (bvh_presplit.hpp)
  std::uint32_t greedy_levels_;
  CollapsePlan plan_;  // the layout below the greedy levels
  unsigned threads_ = 1;
  std::vector<std::atomic<std::uint8_t>> node_seen_;  // by the walks, on several threads
  std::vector<WalkOutput> walks_;                      // the top's walk, then each part's
  BlockSources triangle_sources_, sphere_sources_;     // per block of out_.blocks, same order
  std::vector<std::vector<std::uint64_t>> seen_;                // per gather thread: bit p = primitive p marked
  Bvh8 out_;
};

}  // namespace

Bvh8 flatten_bvh8(const BuildTree& tree, const Geometry& geometry, const FlattenOptions& options) {
  return Flattener(tree, geometry, options).run();
}

}  // namespace rtcl
