#include "rtcl/accel/bvh.hpp"
#include "rtcl/accel/structure_kernels.hpp"

#include <algorithm>
#include <cfloat>
#include <chrono>
#include <cmath>

#include "rtcl/accel/bvh_presplit.hpp"
#include "rtcl/accel/refit.hpp"
#include "rtcl/cl/upload_consuming.hpp"
#include "rtcl/error.hpp"
#include "rtcl/huge_pages.hpp"
#include "rtcl/parallel.hpp"

namespace rtcl {

namespace {

// Primitives per host thread in the boxes pass (parallel.hpp).
constexpr std::size_t kBoundsPartMin = 16384;

// A sphere's box, widened by a few ulps of its coordinates: centre +- radius
// rounded to float may fall just inside the true surface.
Aabb sphere_bounds(const Sphere& s) {
  float magnitude = std::max({std::fabs(s.center.x), std::fabs(s.center.y), std::fabs(s.center.z)}) + s.radius;
  glm::vec3 r(s.radius + 4.0f * FLT_EPSILON * magnitude);
  return {s.center - r, s.center + r};
}

// The parts for_each_kept_triangle splits the triangles into.
unsigned kept_triangle_parts(const Geometry& geometry, unsigned threads) {
  return part_count(geometry.triangles.size(), threads, kBoundsPartMin);
}

// Calls write(part, k, i, box) for the k-th triangle i of non-zero area (k
// from 0 up) and its box, on the build's threads, kept_triangle_parts
// parts, and returns how many there are: each part writes from its own
// first triangle on, then move(from, count, to) moves each later part down
// over the gaps its predecessors' zero-area triangles left.
template <class Write, class Move>
std::size_t for_each_kept_triangle(const Geometry& geometry, unsigned threads, Write write, Move move) {
  const std::size_t triangles = geometry.triangles.size();
  const unsigned parts = kept_triangle_parts(geometry, threads);
  std::vector<std::size_t> part_end(parts);
  for_each_part(triangles, parts, [&](unsigned part, std::size_t begin, std::size_t end) {
    std::size_t out = begin;
    for (std::size_t i = begin; i < end; ++i) {
      const glm::uvec3& t = geometry.triangles[i];
      const glm::vec3 &a = geometry.vertices[t.x], &b = geometry.vertices[t.y], &c = geometry.vertices[t.z];
      if (zero_area(a, b, c)) continue;
      write(part, out++, static_cast<std::uint32_t>(i),
            Aabb{glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c))});
    }
    part_end[part] = out;
  });
  std::size_t kept = 0;
  for (unsigned part = 0; part < parts; ++part) {
    const std::size_t begin = triangles * part / parts, count = part_end[part] - begin;
    if (kept != begin) move(begin, count, kept);
    kept += count;
  }
  return kept;
}

BuildTree build_kind(std::span<const Aabb> bounds, std::span<const std::uint32_t> ids, const BvhConfig& config) {
  if (bounds.empty()) return {};
  if (config.custom_builder) return config.custom_builder(bounds, ids);
  return config.builder == BvhBuilder::ploc ? build_ploc(bounds, ids, config.ploc) : build_sah(bounds, ids, config.sah);
}

// The host image's nodes on the device; with `release`, the host nodes are
// consumed by the upload (upload_consuming) and freed.
cl::Buffer upload_nodes(const Device& device, const Bvh8& bvh, Bvh8* release) {
  const std::size_t bytes = bvh.nodes.size() * sizeof(Bvh8Node);
  if (!release) return device.upload(bvh.nodes.data(), bytes, "BVH nodes");
  cl::Buffer nodes = upload_consuming(device, release->nodes.data(), bytes, "BVH nodes");
  std::vector<Bvh8Node>().swap(release->nodes);
  return nodes;
}

// The host image's blocks on the device; with `release`, consumed and
// freed as the nodes.
DevicePrimitives upload_blocks(const Device& device, const Bvh8& bvh, Bvh8* release) {
  return release ? upload_consuming(device, std::move(release->blocks)) : upload(device, bvh.blocks);
}

class BvhAccel final : public Accel {
 public:
  // Over the host image `bvh`. `release` is null or `bvh` itself, which the
  // caller gives up: each of its arrays is then consumed by its upload,
  // its host pages handed back part by part as they reach the device, so
  // that the build's peak memory never holds the host image and a device
  // copy of it at once (the refit tables are made from the image first).
  BvhAccel(const Device& device, std::string name, const BvhConfig& bvh_config, std::vector<std::string> defines,
           const Bvh8& bvh, Bvh8* release, const Geometry& geometry, AccelStats stats, const AccelConfig& config)
      : Accel(device, std::move(name),
              bvh_config.traversal == BvhTraversal::packet ? packet_kernels(bvh_config, device)
                                                           : single_ray_kernels(bvh_config, device),
              bvh_config.traversal == BvhTraversal::packet || !packets_for_coherent_calls(device.info())
                  ? std::nullopt
                  : std::optional(packet_kernels(bvh_config, device)),
              std::move(defines), stats, config),
        refit_(bvh, geometry),
        nodes_(upload_nodes(device, bvh, release)),
        primitives_(upload_blocks(device, bvh, release)) {}

 private:
  static TraceKernels single_ray_kernels(const BvhConfig& config, const Device& device) {
    return {"accel/bvh.cl", 1, occluder_run_for(config.occluder_run, device.info())};
  }
  static TraceKernels packet_kernels(const BvhConfig& config, const Device& device) {
    return {"accel/bvh_packet.cl", RTCL_BLOCK_WIDTH, occluder_run_for(config.occluder_run, device.info())};
  }

  void set_structure_args(cl::Kernel& kernel, cl_uint first) const override {
    kernel.setArg(first, nodes_);
    kernel.setArg(first + 1, primitives_.triangles);
    kernel.setArg(first + 2, primitives_.spheres);
  }
  bool plain_bvh8() const override { return true; }
  bool refittable() const override { return true; }
  RefitStats refit_structure(const Geometry& geometry, const RefitPolicy& policy, Aabb* bounds) override {
    return refit_.run(*this, nodes_, primitives_.triangles, geometry, policy, bounds);
  }

  Bvh8Refit refit_;
  cl::Buffer nodes_;
  DevicePrimitives primitives_;
};

}  // namespace

BuildTree build_binary_bvh(const Geometry& geometry, const BvhConfig& config, std::size_t* stored) {
  const std::size_t triangles = geometry.triangles.size();
  std::vector<std::uint32_t> sphere_ids(geometry.spheres.size());
  std::vector<Aabb> sphere_boxes(geometry.spheres.size());
  for (std::size_t j = 0; j < geometry.spheres.size(); ++j) {
    sphere_ids[j] = static_cast<std::uint32_t>(triangles + j);
    sphere_boxes[j] = sphere_bounds(geometry.spheres[j]);
  }
  const auto count_stored = [&](std::size_t kept) {
    if (kept + sphere_ids.size() == 0) throw empty_scene_error(geometry);
    if (stored) *stored = kept + sphere_ids.size();
  };
  if (!config.custom_builder && config.builder == BvhBuilder::sah && config.presplit <= 0.0f) {
    // The SAH builder's own array filled here, without box and id arrays
    // in between, and the references' bounds gathered in the same pass.
    auto refs = std::make_unique_for_overwrite<SahRef[]>(triangles);
    advise_huge_pages(refs.get(), triangles * sizeof(SahRef));
    struct alignas(64) PartBounds {  // a cache line each: the parts write theirs on their threads
      SahBounds bounds;
    };
    std::vector<PartBounds> part_bounds(kept_triangle_parts(geometry, bvh_thread_count(config)));
    const std::size_t kept = for_each_kept_triangle(
        geometry, bvh_thread_count(config),
        [&](unsigned part, std::size_t k, std::uint32_t i, const Aabb& box) {
          refs[k] = SahRef::of(box, i);
          part_bounds[part].bounds.add(refs[k]);
        },
        [&](std::size_t from, std::size_t n, std::size_t to) { std::copy_n(refs.get() + from, n, refs.get() + to); });
    count_stored(kept);
    SahBounds bounds;
    for (const PartBounds& b : part_bounds) bounds.add(b.bounds);
    BuildTree triangle_tree = kept ? build_sah(std::move(refs), kept, bounds, config.sah) : BuildTree{};
    return join(std::move(triangle_tree), build_kind(sphere_boxes, sphere_ids, config));
  }
  // The stored primitives (stored_primitives' ids, triangles first) and
  // their boxes.
  std::vector<std::uint32_t> ids(triangles);
  std::vector<Aabb> bounds(triangles);
  const std::size_t kept = for_each_kept_triangle(
      geometry, bvh_thread_count(config),
      [&](unsigned, std::size_t k, std::uint32_t i, const Aabb& box) {
        ids[k] = i;
        bounds[k] = box;
      },
      [&](std::size_t from, std::size_t n, std::size_t to) {
        std::copy_n(ids.begin() + static_cast<std::ptrdiff_t>(from), n, ids.begin() + static_cast<std::ptrdiff_t>(to));
        std::copy_n(bounds.begin() + static_cast<std::ptrdiff_t>(from), n,
                    bounds.begin() + static_cast<std::ptrdiff_t>(to));
      });
  count_stored(kept);
  ids.resize(kept);
  bounds.resize(kept);
  ids.insert(ids.end(), sphere_ids.begin(), sphere_ids.end());
  bounds.insert(bounds.end(), sphere_boxes.begin(), sphere_boxes.end());
  const std::size_t first_sphere = presplit_triangles(geometry, ids, bounds, kept, config.presplit);
  std::span<const Aabb> all_bounds(bounds);
  std::span<const std::uint32_t> all_ids(ids);
  return join(build_kind(all_bounds.first(first_sphere), all_ids.first(first_sphere), config),
              build_kind(all_bounds.subspan(first_sphere), all_ids.subspan(first_sphere), config));
}

unsigned bvh_thread_count(const BvhConfig& config) {
  return config.builder == BvhBuilder::ploc ? config.ploc.thread_count : config.sah.thread_count;
}

Aabb bvh8_lane_box(const Bvh8Node& node, int lane) {
  return {{node.bounds[0][lane], node.bounds[1][lane], node.bounds[2][lane]},
          {node.bounds[3][lane], node.bounds[4][lane], node.bounds[5][lane]}};
}

FlattenOptions flatten_options(const BvhConfig& config) {
  return {.merge_leaves = config.merge_leaves,
          .thread_count = bvh_thread_count(config),
          .split_references = config.presplit > 0.0f,
          .greedy_levels = config.greedy_levels};
}

std::uint32_t bvh_kernel_stack_size(std::uint32_t stack_size) {
  return std::max(32u, (stack_size + 7u) / 8u * 8u);
}

AccelStats bvh_stats(const Geometry& geometry, const GeometryReport& report, const Bvh8& bvh,
                     std::chrono::steady_clock::time_point start) {
  AccelStats stats;
  stats.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  stats.device_bytes = bvh.nodes.size() * sizeof(Bvh8Node) + bvh.blocks.bytes();
  stats.primitive_count = geometry.primitive_count() - report.zero_area_triangles;
  stats.zero_area_skipped = report.zero_area_triangles;
  stats.bounds = geometry.bounds();
  stats.node_count = bvh.nodes.size();
  stats.leaf_count = bvh.blocks.triangles.size() + bvh.blocks.spheres.size();
  return stats;
}

std::vector<std::string> bvh_defines(const Geometry& geometry, const Bvh8& bvh) {
  std::vector<std::string> defines = primitive_defines(geometry);
  defines.push_back("RTCL_STACK_SIZE=" + std::to_string(bvh_kernel_stack_size(bvh.stack_size)));
  return defines;
}

// From this many primitives a build hands its freed temporaries back
// (release_free_heap_memory) between the binary tree and the flattening.
constexpr std::size_t kReleaseFreeHeapPrimitives = std::size_t{1} << 18;

BuiltBvh build_bvh(const Geometry& geometry, const BvhConfig& config) {
  auto start = std::chrono::steady_clock::now();
  GeometryReport report = validate(geometry, ZeroAreaTest::by_caller);
  std::size_t stored = 0;
  BuildTree tree = build_binary_bvh(geometry, config, &stored);
  // The binary builder's temporaries, freed on its worker threads, are
  // handed back before the flattening allocates the 8-wide tree (at 1M
  // triangles the build's peak then reads 81-89 B per triangle instead of
  // 92-117: docs/benchmarks.md, "Large scenes").
  if (geometry.primitive_count() >= kReleaseFreeHeapPrimitives) release_free_heap_memory();
  report.zero_area_triangles = geometry.primitive_count() - stored;
  BuiltBvh built;
  built.bvh = flatten_bvh8(tree, geometry, flatten_options(config));
  built.stats = bvh_stats(geometry, report, built.bvh, start);
  built.defines = bvh_defines(geometry, built.bvh);
  return built;
}

std::unique_ptr<Accel> make_bvh_accel(const Device& device, const BuiltBvh& built, const Geometry& geometry,
                                      const BvhConfig& config, std::string name, const AccelConfig& accel_config) {
  return std::make_unique<BvhAccel>(device, std::move(name), config, built.defines, built.bvh, nullptr, geometry,
                                    built.stats, accel_config);
}

std::unique_ptr<Accel> make_bvh(const Device& device, const Geometry& geometry, const BvhConfig& config,
                                std::string name, const AccelConfig& accel_config) {
  BuiltBvh built = build_bvh(geometry, config);
  return std::make_unique<BvhAccel>(device, std::move(name), config, built.defines, built.bvh, &built.bvh, geometry,
                                    built.stats, accel_config);
}

namespace {

// The options the BVH structures share, each declared once (defaults: the
// config structs' own).
const OptionSpec& merge_leaves_option() {
  static const OptionSpec spec{"merge_leaves", OptionType::boolean, BvhConfig{}.merge_leaves, 0, 0, false,
          "two leaves of a wide node share a block when they fit in 8 lanes and the SAH allows: fewer block "
          "tests and bytes; rarely applies to SAH trees"};
  return spec;
}
const OptionSpec& greedy_levels_option() {
  static const OptionSpec spec{"greedy_levels", OptionType::integer, std::int64_t{BvhConfig{}.greedy_levels}, 0, 1024, false,
          "top wide levels that open their largest child until eight; below, each wide node takes the "
          "SAH-optimal layout of its subtree; 0 = optimal throughout, a level beyond the tree's depth = greedy "
          "throughout"};
  return spec;
}
// SAH and PLOC builds share the node cost's and the leaf cap's defaults.
static_assert(SahConfig{}.node_cost == PlocConfig{}.node_cost && SahConfig{}.max_leaf_size == PlocConfig{}.max_leaf_size);
const OptionSpec& node_cost_option() {
  static const OptionSpec spec{"node_cost", OptionType::real, double{SahConfig{}.node_cost}, 0, 64, true,
          "cost of entering a binary node relative to one 8-primitive block test: higher gives shallower trees "
          "with fuller leaves, lower splits more eagerly"};
  return spec;
}
const OptionSpec& presplit_option() {
  static const OptionSpec spec{"presplit", OptionType::real, double{BvhConfig{}.presplit}, 0, 1024, false,
          "split the references of triangles whose box's area exceeds presplit x the mean (0 = off): helps "
          "coherent rays in scenes of long thin triangles, at some build time"};
  return spec;
}
const OptionSpec& max_leaf_size_option() {
  static const OptionSpec spec{"max_leaf_size", OptionType::integer, std::int64_t{SahConfig{}.max_leaf_size}, 1, 8, false,
          "largest leaf; leaves tend to fill the 8 lanes, a smaller cap only adds nodes"};
  return spec;
}

const std::vector<OptionSpec>& sah_options() {
  static const std::vector<OptionSpec> options = {
      {"bin_count", OptionType::integer, std::int64_t{SahConfig{}.bin_count}, 2, 256, false,
       "SAH bins per axis: more find better planes where density is uneven, at a build cost linear in the bins"},
      {"binning_samples", OptionType::integer, std::int64_t{SahConfig{}.binning_samples}, 0, 0x7fffffff, false,
       "nodes of at least twice this many primitives choose their plane from every k-th one (k = n / this): "
       "less build time on large scenes; 0 bins every primitive"},
      node_cost_option(),
      max_leaf_size_option(),
      {"max_sah_depth", OptionType::integer, std::int64_t{SahConfig{}.max_sah_depth}, 1, 1024, false,
       "deeper nodes split at the object median: bounds the depth and traversal stack, at some quality loss"},
      merge_leaves_option(),
      greedy_levels_option(),
      presplit_option(),
      occluder_run_option(),
  };
  return options;
}

}  // namespace

const std::vector<OptionSpec>& bvh_sah_options() { return sah_options(); }

BvhConfig bvh_config_from(const AccelOptions& o) {
  BvhConfig bvh;
  bvh.merge_leaves = o.boolean("merge_leaves");
  bvh.greedy_levels = static_cast<std::uint32_t>(o.integer("greedy_levels"));
  bvh.presplit = static_cast<float>(o.real("presplit"));
  bvh.occluder_run = static_cast<std::uint32_t>(o.integer("occluder_run"));
  if (o.has("bin_count")) {
    bvh.sah.bin_count = static_cast<std::uint32_t>(o.integer("bin_count"));
    bvh.sah.binning_samples = static_cast<std::uint32_t>(o.integer("binning_samples"));
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

const StructureSpec& bvh_structure() {
  static const StructureSpec spec{
      "bvh", "8-wide BVH, top-down binned SAH; packets of 8 rays for coherent calls on CPU devices", sah_options()};
  return spec;
}

const StructureSpec& bvh_ploc_structure() {
  static const StructureSpec spec{
      "bvh-ploc", "8-wide BVH, bottom-up agglomerative clustering (PLOC)",
      {{"search_radius", OptionType::integer, std::int64_t{PlocConfig{}.search_radius}, 1, 1024, false,
        "clusters searched on each side in Morton order: larger finds closer partners (better trees) at a "
        "build cost linear in r"},
       node_cost_option(),
       max_leaf_size_option(),
       {"max_depth", OptionType::integer, std::int64_t{PlocConfig{}.max_depth}, 1, 1024, false,
        "subtrees reaching this depth are rebuilt by median splits: bounds the stack for chain-forming inputs"},
       merge_leaves_option(),
       greedy_levels_option(),
       presplit_option(),
       occluder_run_option()}};
  return spec;
}

const StructureSpec& bvh_packet_structure() {
  static const StructureSpec spec{"bvh-packet", "the bvh, always traced in packets of 8 rays (for measuring)",
                                  sah_options()};
  return spec;
}

std::unique_ptr<Accel> make_bvh_sah(const Device& device, const Geometry& geometry, const AccelConfig& config) {
  return make_bvh(device, geometry, bvh_config_from(config.options), "bvh", config);
}

std::unique_ptr<Accel> make_bvh_ploc(const Device& device, const Geometry& geometry, const AccelConfig& config) {
  return make_bvh(device, geometry, bvh_config_from(config.options), "bvh-ploc", config);
}

std::unique_ptr<Accel> make_bvh_packet(const Device& device, const Geometry& geometry, const AccelConfig& config) {
  BvhConfig bvh = bvh_config_from(config.options);
  bvh.traversal = BvhTraversal::packet;
  return make_bvh(device, geometry, bvh, "bvh-packet", config);
}

}  // namespace rtcl
