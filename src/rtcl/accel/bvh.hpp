// 8-wide bounding volume hierarchy: a binary build tree (binned SAH or PLOC)
// collapsed into Bvh8Node records (kernels/shared/layouts.h) whose eight
// child boxes the kernel tests at once in float8 lanes, with leaves that are
// blocks of up to eight triangles or eight spheres.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/accel/structure_kernels.hpp"
#include "rtcl/accel/build_tree.hpp"
#include "rtcl/accel/bvh_ploc.hpp"
#include "rtcl/accel/bvh_sah.hpp"
#include "rtcl/accel/primitive_blocks.hpp"
#include "rtcl/layouts.hpp"

namespace rtcl {

enum class BvhBuilder {
  sah,   // top-down binned SAH (bvh_sah.hpp): the default, best trace speed
  ploc,  // bottom-up clustering (bvh_ploc.hpp)
};

// The two kernels over the same tree, same closest t: single ray (one ray per
// work-item, a node's 8 children in float8 lanes, kernels/accel/bvh.cl) and
// packet (8 consecutive rays per work-item in float8 lanes,
// kernels/accel/bvh_packet.cl). Packets win only when the 8 rays are alike
// (primary rays in pixel order; shadow rays to one light break even);
// scattered rays such as diffuse bounces trace faster one per work-item.
// The rates of both kernels per ray kind: docs/benchmarks.md.
enum class BvhTraversal {
  by_coherence,  // packets for Coherence::coherent calls on CPU devices (packets_for_coherent_calls), else single rays
  packet,        // packets for every call (measuring and testing the packet kernel on any rays)
};

struct BvhConfig {
  BvhBuilder builder = BvhBuilder::sah;
  BvhTraversal traversal = BvhTraversal::by_coherence;
  SahConfig sah;
  PlocConfig ploc;
  // Collapse: two leaves of one wide node share a block when their
  // primitives fit in eight lanes and the SAH does not object (the union's
  // area is at most the sum of theirs): one block test instead of two, fewer
  // bytes. Rarely applies to SAH trees, whose leaves are already full;
  // off changes nothing else.
  bool merge_leaves = true;
  // Collapse: the wide nodes of the top greedy_levels levels (the root's
  // is level 1) keep opening their child of largest area until they have
  // eight children; below them each wide node takes the SAH-optimal layout
  // of its subtree (bvh_collapse.hpp). 0: optimal throughout; a level
  // beyond the tree's depth: greedy throughout. The default 2 traces
  // nearly every bench/ ray set faster than either extreme
  // (docs/benchmarks.md).
  std::uint32_t greedy_levels = 2;
  // Early split clipping (bvh_presplit.hpp): triangles whose box's surface
  // area exceeds presplit times the mean enter the builder as several
  // references; 0 = off (the default). It pays on scenes of long thin
  // triangles across large boxes (architecture such as sponza: coherent
  // rays), costs some build time, and leaves evenly tessellated meshes
  // almost untouched; figures: docs/benchmarks.md.
  float presplit = 0.0f;
  // Occlusion (Query::any): consecutive rays per work-item (packets of 8 in
  // the packet kernel), each tested first against the leaf that blocked the
  // previous one (a shadow cache, kernels/shared/trace.h and packet.h):
  // shadow rays in pixel order that share an occluder skip the traversal.
  // 1 = no such test; 0 = by device (occluder_run_for, accel.hpp). Hit or
  // miss never depends on it.
  std::uint32_t occluder_run = 0;
  // A binary builder of the caller's in place of `builder`: called once per
  // kind of primitive the geometry has (triangles, spheres; never with
  // none) with their boxes and ids, it returns a tree over exactly those ids
  // with leaves of 1..8 (the flatten checks it and throws Error otherwise).
  // For comparing builders on the same kernels: Embree's binned SAH tree
  // (bench/support/embree_baseline.hpp) is traced this way.
  std::function<BuildTree(std::span<const Aabb>, std::span<const std::uint32_t>)> custom_builder;
};

// The host image of what the kernel reads.
struct Bvh8 {
  std::vector<Bvh8Node> nodes;   // nodes[0] is the root
  PrimitiveBlocks blocks;        // primitives in leaf order
  // Traversal stack entries the kernel needs for this tree (exact): the
  // maximum over nodes of their children plus (children - 1) of each
  // ancestor (kernels/accel/bvh.cl).
  std::uint32_t stack_size = 0;
  std::uint32_t depth = 0;       // wide levels on the longest root-to-leaf path
  std::vector<std::uint32_t> zero_area_triangles;  // ids in no leaf (zero area), ascending
};

// The box of `node`'s lane `lane` (0..7); an empty slot's is empty (lower
// +inf, upper -inf).
Aabb bvh8_lane_box(const Bvh8Node& node, int lane);

// The binary tree over the geometry's stored primitives (zero-area
// triangles skipped); leaves hold primitive ids. Triangles and spheres are
// built separately and joined under one root, so no leaf mixes them.
// Geometry must have passed validate() (ZeroAreaTest::by_caller suffices:
// a scene of zero-area triangles only throws empty_scene_error here). With
// config.presplit > 0 a large triangle may sit in several leaves (flatten
// with split_references). *stored, when given, receives the number of
// stored primitives.
BuildTree build_binary_bvh(const Geometry& geometry, const BvhConfig& config = {}, std::size_t* stored = nullptr);

// Collapses the binary tree into 8-wide nodes: a wide node of the top
// `greedy_levels` levels takes the two children of a binary node and keeps
// opening the child with the largest surface area until it has eight
// children or only leaves; one below takes the SAH-optimal layout of its
// subtree, whole subtrees of up to eight primitives as one block
// (bvh_collapse.hpp); either then merges small sibling leaves when
// `merge_leaves`. Checked: throws Error when the tree
// does not hold every stored primitive of `geometry` exactly once in leaves
// of 1..8 primitives of one kind whose boxes contain them, or its stack need
// exceeds kBvhMaxStackSize. With `split_references` (a presplit build) a
// triangle may sit in several leaves, each of whose boxes must meet its
// box, once per block. The blocks are filled on up to `thread_count`
// threads (0 = all hardware threads); the result does not depend on the
// threads.
struct FlattenOptions {
  bool merge_leaves = true;
  unsigned thread_count = 0;
  bool split_references = false;
  std::uint32_t greedy_levels = BvhConfig{}.greedy_levels;
};
Bvh8 flatten_bvh8(const BuildTree& tree, const Geometry& geometry, const FlattenOptions& options = {});

// The flatten options of a tree built by build_binary_bvh(geometry, config):
// the config's merge_leaves, threads and greedy_levels, split references
// where it presplits.
FlattenOptions flatten_options(const BvhConfig& config);

// The threads the config's builder may use (its thread_count).
unsigned bvh_thread_count(const BvhConfig& config);

// The largest traversal stack the kernel is compiled for (entries of 8 bytes
// per work-item); a deeper tree is refused with an Error.
inline constexpr std::uint32_t kBvhMaxStackSize = 1024;

// The RTCL_STACK_SIZE the kernel is compiled with for a tree needing
// `stack_size` entries: a multiple of 8, at least 32, so that small trees
// share one compiled program (a program's compile costs about a second on
// PoCL) while a large tree keeps its own tight stack.
std::uint32_t bvh_kernel_stack_size(std::uint32_t stack_size);

// Builds, flattens and uploads; stats().build_ms covers build + flatten.
// `name` is what Accel::name() reports ("bvh", "bvh-ploc").
std::unique_ptr<Accel> make_bvh(const Device& device, const Geometry& geometry, const BvhConfig& config = {},
                                std::string name = "bvh", const AccelConfig& accel_config = {});

// make_bvh in its two steps, for a caller that keeps the host image (the
// two-level scene's bottom levels, src/rtcl/scene/two_level.hpp): the build
// and flatten over the geometry (validated here, as make_bvh does), and the
// structure over that image (uploaded; the image may go after).
struct BuiltBvh {
  Bvh8 bvh;
  AccelStats stats;
  std::vector<std::string> defines;  // bvh_defines
};
BuiltBvh build_bvh(const Geometry& geometry, const BvhConfig& config = {});
std::unique_ptr<Accel> make_bvh_accel(const Device& device, const BuiltBvh& built, const Geometry& geometry,
                                      const BvhConfig& config = {}, std::string name = "bvh",
                                      const AccelConfig& accel_config = {});

// The options of the SAH-built structures ("bvh", "bvh-packet"), and the
// BvhConfig a structure's resolved options (make_accel: every declared
// option present) give (for structures built on the BVH, bvh_mixed.hpp).
const std::vector<OptionSpec>& bvh_sah_options();
BvhConfig bvh_config_from(const AccelOptions& options);

// The stats of a BVH built since `start` over validated `geometry`, and the
// defines of its traversal kernels (bvh and bvh-mixed).
AccelStats bvh_stats(const Geometry& geometry, const GeometryReport& report, const Bvh8& bvh,
                     std::chrono::steady_clock::time_point start);
std::vector<std::string> bvh_defines(const Geometry& geometry, const Bvh8& bvh);

// Their registry entries; the options set the SahConfig / PlocConfig fields
// of the same name and BvhConfig::merge_leaves.
const StructureSpec& bvh_structure();
const StructureSpec& bvh_ploc_structure();
const StructureSpec& bvh_packet_structure();

// The registered structures: "bvh" (binned SAH), "bvh-ploc" (PLOC) and
// "bvh-packet" (binned SAH, BvhTraversal::packet), configured by
// config.options as make_accel resolved them (the registry's factories:
// every declared option present, defaults filled in).
std::unique_ptr<Accel> make_bvh_sah(const Device& device, const Geometry& geometry, const AccelConfig& config);
std::unique_ptr<Accel> make_bvh_ploc(const Device& device, const Geometry& geometry, const AccelConfig& config);
std::unique_ptr<Accel> make_bvh_packet(const Device& device, const Geometry& geometry, const AccelConfig& config);

}  // namespace rtcl
