#include "rtcl/accel/bvh_sah.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <condition_variable>
#include <limits>
#include <memory>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

#include "rtcl/error.hpp"
#include "rtcl/huge_pages.hpp"
#include "rtcl/layouts.hpp"
#include "rtcl/parallel.hpp"
#include "rtcl/thread_pool.hpp"

namespace rtcl {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr std::uint32_t kMaxBins = 256;
// Ranges binned with two sets of bins, and with four (bin_range); a root
// binned by several threads, each part at least half this (find_split).
constexpr std::uint32_t kTwoSetMin = 1024;
constexpr std::uint32_t kFourSetMin = 4096;
constexpr std::uint32_t kParallelBinMin = 16384;
// A child index in a subtree's nodes that names another subtree's root.
constexpr std::uint32_t kSubtreeRef = 0x80000000u;

// The split search, the binning and the partition are compiled twice, for
// AVX2 and for the baseline x86-64, and the loader picks by the CPU (GCC's
// target_clones, an ifunc), as Embree picks its builders by ISA: the
// three-operand VEX forms and blends of AVX2 shorten the builds of small
// scenes, where these loops dominate (docs/benchmarks.md). AVX2
// does not include FMA, so no contraction: the same arithmetic, and the
// same tree, on every x86-64 CPU. Left out with sanitizers and elsewhere.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
#define RTCL_AVX2_CLONE [[gnu::target_clones("avx2", "default")]]
#else
#define RTCL_AVX2_CLONE
#endif

// Four floats in one SIMD register (GCC/Clang vector extension): x, y, z
// and a spare lane. Boxes grow with two 4-wide min/max operations.
typedef float Float4 __attribute__((vector_size(16)));
typedef int Int4 __attribute__((vector_size(16)));
typedef std::uint32_t UInt4 __attribute__((vector_size(16)));

inline Float4 min4(Float4 a, Float4 b) { return b < a ? b : a; }
inline Float4 max4(Float4 a, Float4 b) { return a < b ? b : a; }

// Trivially constructible (bins live uninitialised on the stack): start
// from Box::empty().
struct Box {
  Float4 lo, hi;

  static Box empty() { return {Float4{kInf, kInf, kInf, kInf}, Float4{-kInf, -kInf, -kInf, -kInf}}; }

  void grow(const Box& b) {
    lo = min4(lo, b.lo);
    hi = max4(hi, b.hi);
  }
  void grow_point(Float4 p) {
    lo = min4(lo, p);
    hi = max4(hi, p);
  }
  float area() const {
    Float4 e = hi - lo;
    return e[0] < 0.0f ? 0.0f : 2.0f * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0]);
  }
  Aabb aabb() const { return {{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}}; }
};

// 8-wide vectors: a box as its lower corner and its upper one negated
// (exact), so that one 8-wide min grows it (the bins, the split search's
// sweep and the partition's centre bounds). Passed by reference only: by
// value, a function's ABI would change without AVX.
typedef float Float8 __attribute__((vector_size(32)));
typedef int Int8 __attribute__((vector_size(32)));

// A primitive during the build (SahRef, bvh_sah.hpp), partitioned in place
// so that every subtree's primitives stay contiguous.
inline std::uint32_t id_of(const SahRef& r) { return std::bit_cast<std::uint32_t>(r.upper[3]); }
// Its box, lane 3 zero in both corners (lower[3] is zero by SahRef's
// contract; upper[3] is masked). Lane 3 of the record's upper corner holds
// the id's bits, a denormal float for ids below 2^23: arithmetic on it
// can take a microcode assist (on the order of 100 cycles per operation),
// and carried into the bins' boxes it would reach every area of the split
// search. Masked, no arithmetic of the build touches it.
// Read as two vector loads (a may_alias vector type, not a byte copy,
// which the compiler staged through the stack in the hot loops).
typedef float Float4Alias __attribute__((vector_size(16), may_alias));
inline Box box_of(const SahRef& r) {
  const auto* v = reinterpret_cast<const Float4Alias*>(&r);
  return {v[0], std::bit_cast<Float4>(std::bit_cast<Int4>(Float4(v[1])) & Int4{-1, -1, -1, 0})};
}
// Box centre, halves first (no overflow near the float range's ends); lane
// 3 zero.
inline Float4 centre_of(const SahRef& r) {
  const Box b = box_of(r);
  return 0.5f * b.lo + 0.5f * b.hi;
}

inline float blocks(std::uint32_t n) { return static_cast<float>((n + RTCL_BLOCK_WIDTH - 1) / RTCL_BLOCK_WIDTH); }
// blocks() of each lane; the block counts (< 2^29) convert as signed ints.
inline Float4 blocks4(UInt4 n) {
  return __builtin_convertvector(std::bit_cast<Int4>((n + (RTCL_BLOCK_WIDTH - 1)) / RTCL_BLOCK_WIDTH), Float4);
}

// The bins of a centre: bins_of(centre, offset, scale, last_bin), count
// bins per axis.
struct BinMap {
  Float4 offset = {0, 0, 0, 0}, scale = {0, 0, 0, 0}, last_bin = {0, 0, 0, 0};
  std::uint32_t count = 0;
};

struct Split {
  int axis = -1;          // -1: no plane separates the centroids
  std::uint32_t bin = 0;  // left side: bins [0, bin)
  float cost = kInf;      // area-weighted, in block tests
  BinMap map;             // the bins of a centre
  // The sides' boxes from the bins; when only some references were binned
  // (sampled), the partition computes them instead.
  Box left = Box::empty(), right = Box::empty();
  bool sampled = false;
};

// Bin indices of a centre along each axis, in [0, last_bin]; clamped as
// floats first, so that the conversion is defined for any input (NaN: 0).
inline Int4 bins_of(Float4 centre, Float4 offset, Float4 scale, Float4 last_bin) {
  Float4 k = (centre - offset) * scale;
  Float4 zero = {0.0f, 0.0f, 0.0f, 0.0f};
  k = zero < k ? k : zero;  // NaN -> 0
  k = min4(k, last_bin);
  return __builtin_convertvector(k, Int4);
}

// Per axis and bin: the bounds of the references whose centre falls in it,
// and their number. Trivially constructible: clear() the bins in use. A
// bin's box is one 8-wide vector, its lower corner and its upper one
// negated (exact), so that one min grows it (box() reads it back).
struct Bins {
  Float8 bounds[3][kMaxBins];
  std::uint32_t count[3][kMaxBins];

  void clear(std::uint32_t bins) {
    for (int a = 0; a < 3; ++a)
      for (std::uint32_t k = 0; k < bins; ++k) {
        bounds[a][k] = Float8{kInf, kInf, kInf, kInf, kInf, kInf, kInf, kInf};
        count[a][k] = 0;
      }
  }
  // b: a box as lower corner and negated upper one.
  void add(Int4 k, const Float8& b) {
    for (int a = 0; a < 3; ++a) {
      Float8& to = bounds[a][k[a]];
      to = b < to ? b : to;
      ++count[a][k[a]];
    }
  }
  void merge(const Bins& other, std::uint32_t bins) {
    for (int a = 0; a < 3; ++a)
      for (std::uint32_t k = 0; k < bins; ++k) {
        const Float8& b = other.bounds[a][k];
        bounds[a][k] = b < bounds[a][k] ? b : bounds[a][k];
        count[a][k] += other.count[a][k];
      }
  }
  Box box(int axis, std::uint32_t k) const {
    const Float8& v = bounds[axis][k];
    return {__builtin_shufflevector(v, v, 0, 1, 2, 3), -__builtin_shufflevector(v, v, 4, 5, 6, 7)};
  }
};

// A node's primitives: refs[begin, end), their bounds and their centres'.
struct Range {
  std::uint32_t begin, end;
  Box bounds, centres;
};

class SahBuilder {
 public:
  // Over boxes and ids (each stored as a SahRef). Throws check_builder_input's
  // error for the first invalid box (the boxes are tested in the
  // constructor's parallel pass over them).
  SahBuilder(std::span<const Aabb> bounds, std::span<const std::uint32_t> ids, const SahConfig& config)
      : SahBuilder(std::make_unique_for_overwrite<SahRef[]>(bounds.size()), bounds.size(), config,
                   [&](std::size_t i) { return SahRef::of(bounds[i], ids[i]); }) {}
  // Over refs the caller filled; tested as above.
  SahBuilder(std::unique_ptr<SahRef[]> refs, std::size_t count, const SahConfig& config)
      : SahBuilder(std::move(refs), count, config, Filled{}) {}
  // Over refs the caller filled, tested and bounded (build_sah's contract).
  SahBuilder(std::unique_ptr<SahRef[]> refs, std::size_t count, const SahBounds& bounds, const SahConfig& config)
      : config_(config), refs_(std::move(refs)), ref_count_(count) {
    thread_count_ = thread_count(config, count);
    auto box = [](const Aabb& b) {
      return Box{Float4{b.lower.x, b.lower.y, b.lower.z, 0.0f}, Float4{b.upper.x, b.upper.y, b.upper.z, 0.0f}};
    };
    root_ = {0, static_cast<std::uint32_t>(count), box(bounds.boxes), box(bounds.centres)};
  }

  BuildTree run() {
    BuildTree tree;
    if (ref_count_ == 0) return tree;
    const std::uint32_t root_subtree = new_subtree(ref_count_);
    if (thread_count_ > 1 && ref_count_ >= kParallelBinMin)
      build(*subtrees_[root_subtree], 0, root_, 1, Children::as_tasks);
    else
      add_task({root_subtree, root_, 1});
    run_jobs(thread_count_, [this](unsigned) { work(); });
    assemble(tree.nodes);
    reserve_faulted(tree.prims, ref_count_, thread_count_);
    tree.prims.resize(ref_count_);
    for_each_part(ref_count_, part_count(ref_count_, thread_count_, config_.parallel_min_primitives),
                  [&](unsigned, std::size_t begin, std::size_t end) {
                    for (std::size_t i = begin; i < end; ++i) tree.prims[i] = id_of(refs_[i]);
                  });
    return tree;
  }

 private:
  // refs_[i] = ref_of(i) for every i (Filled: refs_ as it is), each box
  // tested (finite, lower <= upper), and the root's bounds, on the
  // builder's threads.
  struct Filled {};
  template <class RefOf>
  SahBuilder(std::unique_ptr<SahRef[]> refs, std::size_t count, const SahConfig& config, RefOf ref_of)
      : config_(config), refs_(std::move(refs)), ref_count_(count) {
    thread_count_ = thread_count(config, count);
    const unsigned parts = part_count(ref_count_, thread_count_, config.parallel_min_primitives);
    std::vector<Range> part_ranges(parts);
    for_each_part(ref_count_, parts, [&](unsigned part, std::size_t begin, std::size_t end) {
      Box box = Box::empty(), centres = Box::empty();
      for (std::size_t i = begin; i < end; ++i) {
        SahRef r;
        if constexpr (std::is_same_v<RefOf, Filled>) {
          r = refs_[i];
        } else {
          r = ref_of(i);
          refs_[i] = r;
        }
        const Box b = box_of(r);
        // finite with lo <= hi (false for NaN) on every axis (lanes 0..2)
        const Int4 ok = (b.lo > -kInf) & (b.hi < kInf) & (b.lo <= b.hi);
        if (!(ok[0] & ok[1] & ok[2])) throw builder_box_error(id_of(r), "SAH builder");
        box.grow(b);
        centres.grow_point(centre_of(r));
      }
      part_ranges[part] = {0, 0, box, centres};
    });
    root_ = {0, static_cast<std::uint32_t>(ref_count_), Box::empty(), Box::empty()};
    for (const Range& r : part_ranges) {
      root_.bounds.grow(r.bounds);
      root_.centres.grow(r.centres);
    }
  }

  // The threads that build count references: config's (0 = every hardware
  // thread), one below two tasks' worth.
  static unsigned thread_count(const SahConfig& config, std::size_t count) {
    if (count < 2 * config.parallel_min_primitives) return 1;
    return config.thread_count ? config.thread_count : std::max(1u, std::thread::hardware_concurrency());
  }

  // Best SAH plane over bins of the centroids in the range. Nodes use n / 8
  // bins, at least 8 and at most bin_count: a node's cost is O(n + bins),
  // and the bins that matter are those of the large nodes near the root.
  // Not inlined: its bins (~28 KB a set) must not sit in every frame of the
  // recursion.
  [[gnu::noinline]] RTCL_AVX2_CLONE Split find_split(const Range& range, bool root) const {
    const std::uint32_t n = range.end - range.begin;
    BinMap map;
    map.count = std::min(config_.bin_count, std::max(8u, n / 8));
    const auto last = static_cast<float>(map.count - 1);
    map.last_bin = Float4{last, last, last, last};
    bool usable[3];
    for (int a = 0; a < 3; ++a) {
      float extent = range.centres.hi[a] - range.centres.lo[a];
      map.offset[a] = range.centres.lo[a];
      float sc = static_cast<float>(map.count) * (1.0f - 4.0f * std::numeric_limits<float>::epsilon()) / extent;
      usable[a] = extent > 0.0f && std::isfinite(extent) && std::isfinite(sc) && sc > 0.0f;
      map.scale[a] = usable[a] ? sc : 0.0f;
    }
    Bins bins;
    bins.clear(map.count);
    const std::uint32_t stride = sample_stride(n);
    if (root && thread_count_ > 1 && n >= kParallelBinMin) {
      // the root: no other thread has work yet, so each bins a part
      const unsigned parts = part_count(n, thread_count_, kParallelBinMin / 2);
      std::vector<std::unique_ptr<Bins>> part_bins(parts);
      for_each_part(n, parts, [&](unsigned part, std::size_t begin, std::size_t end) {
        Bins* b = &bins;
        if (part > 0) {
          part_bins[part] = std::make_unique<Bins>();
          b = part_bins[part].get();
          b->clear(map.count);
        }
        // the part's first reference of the stride's (counted from the range's
        // begin, so that the samples do not depend on the parts)
        const auto from = static_cast<std::uint32_t>((begin + stride - 1) / stride * stride);
        bin_range(range.begin + from, range.begin + static_cast<std::uint32_t>(end), stride, map, *b);
      });
      for (unsigned part = 1; part < parts; ++part) bins.merge(*part_bins[part], map.count);
    } else {
      bin_range(range.begin, range.end, stride, map, bins);
    }
    // The sweep, the three axes at once in the lanes of Float4 / UInt4
    // (lane 3 unused): per lane the same arithmetic as one axis at a time,
    // and the same plane (the first of least cost, axes in order x, y, z),
    // without a branch on each cost (the comparisons are unpredictable).
    const std::uint32_t k_count = map.count;
    Float4 right_area[kMaxBins];
    UInt4 right_n[kMaxBins];
    // acc: each axis's box in the bins' form (Bins)
    const Float8 empty = {kInf, kInf, kInf, kInf, kInf, kInf, kInf, kInf};
    Float8 acc[3] = {empty, empty, empty};
    const auto grow = [&](std::uint32_t k) {
      for (int a = 0; a < 3; ++a) acc[a] = bins.bounds[a][k] < acc[a] ? bins.bounds[a][k] : acc[a];
    };
    // Box::area of acc[0..2] in lanes 0..2 (lane 3: 0), the same arithmetic
    // (upper - lower) per lane
    const auto areas = [&] {
      Float4 e[3];
      for (int a = 0; a < 3; ++a)
        e[a] = -__builtin_shufflevector(acc[a], acc[a], 4, 5, 6, 7) - __builtin_shufflevector(acc[a], acc[a], 0, 1, 2, 3);
      const Float4 x = {e[0][0], e[1][0], e[2][0], 0.0f}, y = {e[0][1], e[1][1], e[2][1], 0.0f},
                   z = {e[0][2], e[1][2], e[2][2], 0.0f};
      const Float4 area = 2.0f * (x * y + y * z + z * x);
      return x < Float4{0.0f, 0.0f, 0.0f, 0.0f} ? Float4{0.0f, 0.0f, 0.0f, 0.0f} : area;
    };
    UInt4 count = {0, 0, 0, 0};
    for (std::uint32_t k = k_count - 1; k > 0; --k) {
      grow(k);
      count += UInt4{bins.count[0][k], bins.count[1][k], bins.count[2][k], 0};
      right_area[k] = areas();
      right_n[k] = count;
    }
    const UInt4 zero = {0, 0, 0, 0};
    const UInt4 usable4 = {usable[0] ? ~0u : 0u, usable[1] ? ~0u : 0u, usable[2] ? ~0u : 0u, 0u};
    Float4 best_cost = {kInf, kInf, kInf, kInf};
    UInt4 best_bin = zero;
    acc[0] = acc[1] = acc[2] = empty;
    count = zero;
    for (std::uint32_t k = 1; k < k_count; ++k) {
      grow(k - 1);
      count += UInt4{bins.count[0][k - 1], bins.count[1][k - 1], bins.count[2][k - 1], 0};
      const Float4 cost = areas() * blocks4(count) + right_area[k] * blocks4(right_n[k]);
      const UInt4 better = usable4 & (count != zero) & (right_n[k] != zero) & (cost < best_cost);
      best_cost = better ? cost : best_cost;
      best_bin = better ? UInt4{k, k, k, k} : best_bin;
    }
    Split best;
    for (int a = 0; a < 3; ++a)
      if (best_cost[a] < best.cost) {
        best.cost = best_cost[a];
        best.axis = a;
        best.bin = best_bin[a];
      }
    if (best.axis >= 0) {
      int a = best.axis;
      best.map = map;
      best.sampled = stride > 1;
      for (std::uint32_t k = 0; k < k_count; ++k) (k < best.bin ? best.left : best.right).grow(bins.box(a, k));
    }
    return best;
  }

  // Every how many references find_split bins one in a node of n
  // (SahConfig::binning_samples).
  std::uint32_t sample_stride(std::uint32_t n) const {
    return config_.binning_samples == 0 ? 1u : (n / config_.binning_samples) | 1u;
  }

  // Whether a leaf of the range's at most RTCL_BLOCK_WIDTH references is
  // cheaper than every split of it: then find_split need not run, and the
  // node is a leaf as find_split's cost would have made it. Both sides of a
  // split are one block each, so a split costs at least the area of its two
  // sides' boxes; take the three references of largest box area, b0..b2:
  // whichever two-sided partition of them a split makes (all on one side,
  // or one pair on a side and the third on the other), its sides' areas sum
  // to at least one of the four bounds below. Float areas only grow with
  // the box and float sums with their terms, so the bound holds for the
  // costs find_split computes. It skips the split search at most small
  // nodes (at most 8 references) of real meshes.
  bool leaf_wins_any_split(const Range& range, float area) const {
    std::uint32_t top[3] = {range.begin, range.begin, range.begin};
    float top_area[3] = {-1.0f, -1.0f, -1.0f};
    for (std::uint32_t i = range.begin; i < range.end; ++i) {
      float a = box_of(refs_[i]).area();
      std::uint32_t r = i;
      for (int k = 0; k < 3; ++k)
        if (a > top_area[k]) {
          std::swap(a, top_area[k]);
          std::swap(r, top[k]);
        }
    }
    for (float& a : top_area) a = std::max(a, 0.0f);  // fewer than three references
    auto pair = [&](int x, int y) {
      Box b = box_of(refs_[top[x]]);
      b.grow(box_of(refs_[top[y]]));
      return b;
    };
    Box all = pair(0, 1);
    all.grow(box_of(refs_[top[2]]));
    const float lower = std::min({all.area(), pair(0, 1).area() + top_area[2], pair(0, 2).area() + top_area[1],
                                  pair(1, 2).area() + top_area[0]});
    return area * blocks(range.end - range.begin) <= config_.node_cost * area + lower;
  }

  // Adds refs_[begin], refs_[begin + stride], ... (those below end) to
  // bins. Long runs rotate through two or four sets of bins: consecutive
  // references often fall into the same bin (on a connected mesh, most of
  // them do deep in the tree), and with one set each update would wait for
  // the store of the one before. Bins merge exactly (min, max and integer
  // sums), so the sets change no result. map is copied: the stores to bins
  // could alias it, and the loops would reload it.
  RTCL_AVX2_CLONE void bin_range(std::uint32_t begin, std::uint32_t end, std::uint32_t stride, const BinMap& map_in,
                                 Bins& bins) const {
    const BinMap map = map_in;
    const auto add = [&](Bins& to, std::uint32_t i) {
      const Box b = box_of(refs_[i]);
      to.add(bins_of(centre_of(refs_[i]), map.offset, map.scale, map.last_bin),
             __builtin_shufflevector(b.lo, -b.hi, 0, 1, 2, 3, 4, 5, 6, 7));
    };
    const std::uint32_t samples = begin < end ? (end - begin - 1) / stride + 1 : 0;
    std::uint32_t i = begin, k = 0;
    if (samples >= kTwoSetMin) {
      const unsigned extra_sets = samples >= kFourSetMin ? 3 : 1;
      std::unique_ptr<Bins[]> extra(new Bins[extra_sets]);
      for (unsigned e = 0; e < extra_sets; ++e) extra[e].clear(map.count);
      if (extra_sets == 3) {
        for (; k + 3 < samples; k += 4, i += 4 * stride) {
          add(bins, i);
          add(extra[0], i + stride);
          add(extra[1], i + 2 * stride);
          add(extra[2], i + 3 * stride);
        }
      } else {
        for (; k + 1 < samples; k += 2, i += 2 * stride) {
          add(bins, i);
          add(extra[0], i + stride);
        }
      }
      for (unsigned e = 0; e < extra_sets; ++e) bins.merge(extra[e], map.count);
    }
    for (; k < samples; ++k, i += stride) add(bins, i);
  }

  // Partitions the range by the split's plane; fills both sides' centre
  // bounds, and with kBoxes (a sampled split: partition_with_boxes) their
  // boxes, which otherwise come from the bins. Both sides are non-empty
  // (each holds a binned reference).
  // Branch-free (Lomuto: each reference is swapped with the first of the
  // right side, which then grows by one unless it went left): which side a
  // reference goes to is unpredictable, and a branch on it mispredicted
  // about every other time.
  template <bool kBoxes>
  [[gnu::always_inline]] inline std::uint32_t partition_impl(const Range& range, const Split& split, Range& left,
                                                            Range& right) {
    const int a = split.axis;
    const float offset = split.map.offset[a], scale = split.map.scale[a];
    const auto bin = static_cast<float>(split.bin);
    const Float8 inf = {kInf, kInf, kInf, kInf, kInf, kInf, kInf, kInf};
    // The centre bounds in locals, in registers for the loop (refs_' stores
    // could alias the callers' ranges), each as its lower corner and its
    // negated upper one: one 8-wide min grows both.
    Float8 left_centres = __builtin_shufflevector(left.centres.lo, -left.centres.hi, 0, 1, 2, 3, 4, 5, 6, 7);
    Float8 right_centres = __builtin_shufflevector(right.centres.lo, -right.centres.hi, 0, 1, 2, 3, 4, 5, 6, 7);
    Float8 left_boxes = inf, right_boxes = inf;
    SahRef* refs = refs_.get();
    std::uint32_t store = range.begin;
    for (std::uint32_t i = range.begin; i < range.end; ++i) {
      // bins_of(c)[a] < bin: the same arithmetic, before the clamps, which
      // cannot move a value across bin >= 1; c[a] from the record's own
      // floats in the array, as centre_of computes it (a is not the id's
      // lane)
      const float centre_a = 0.5f * refs[i].lower[a] + 0.5f * refs[i].upper[a];
      const SahRef r = refs[i];
      const Float4 c = centre_of(r);
      const bool goes_left = (centre_a - offset) * scale < bin;
      refs[i] = refs[store];
      refs[store] = r;
      store += goes_left;
      const Int8 mask = Int8{0, 0, 0, 0, 0, 0, 0, 0} - static_cast<int>(goes_left);
      const Float8 c8 = __builtin_shufflevector(c, -c, 0, 1, 2, 3, 4, 5, 6, 7);
      const Float8 to_left = mask ? c8 : inf, to_right = mask ? inf : c8;
      left_centres = to_left < left_centres ? to_left : left_centres;
      right_centres = to_right < right_centres ? to_right : right_centres;
      if constexpr (kBoxes) {
        const Box b = box_of(r);
        const Float8 b8 = __builtin_shufflevector(b.lo, -b.hi, 0, 1, 2, 3, 4, 5, 6, 7);
        const Float8 box_left = mask ? b8 : inf, box_right = mask ? inf : b8;
        left_boxes = box_left < left_boxes ? box_left : left_boxes;
        right_boxes = box_right < right_boxes ? box_right : right_boxes;
      }
    }
    if constexpr (kBoxes) {
      left.bounds.grow({__builtin_shufflevector(left_boxes, left_boxes, 0, 1, 2, 3),
                        -__builtin_shufflevector(left_boxes, left_boxes, 4, 5, 6, 7)});
      right.bounds.grow({__builtin_shufflevector(right_boxes, right_boxes, 0, 1, 2, 3),
                         -__builtin_shufflevector(right_boxes, right_boxes, 4, 5, 6, 7)});
    }
    left.centres = {__builtin_shufflevector(left_centres, left_centres, 0, 1, 2, 3),
                    -__builtin_shufflevector(left_centres, left_centres, 4, 5, 6, 7)};
    right.centres = {__builtin_shufflevector(right_centres, right_centres, 0, 1, 2, 3),
                     -__builtin_shufflevector(right_centres, right_centres, 4, 5, 6, 7)};
    return store;
  }

  RTCL_AVX2_CLONE std::uint32_t partition(const Range& range, const Split& split, Range& left, Range& right) {
    return partition_impl<false>(range, split, left, right);
  }
  RTCL_AVX2_CLONE std::uint32_t partition_with_boxes(const Range& range, const Split& split, Range& left,
                                                     Range& right) {
    return partition_impl<true>(range, split, left, right);
  }
  std::uint32_t partition_any(const Range& range, const Split& split, Range& left, Range& right) {
    return split.sampled ? partition_with_boxes(range, split, left, right) : partition(range, split, left, right);
  }

  // The root's partition: each half of the range partitioned as by
  // partition(), on two threads when there are, then the first half's right
  // run and the second half's left run exchanged (the shorter one's length
  // of references). The same order, and so the same tree, on any number of
  // threads.
  std::uint32_t partition_halves(const Range& range, const Split& split, Range& left, Range& right) {
    const std::uint32_t mid = range.begin + (range.end - range.begin) / 2;
    const Range halves[2] = {{range.begin, mid, range.bounds, range.centres}, {mid, range.end, range.bounds, range.centres}};
    Range sides[2][2] = {{left, right}, {left, right}};  // [half][left, right]: centre bounds (and boxes)
    std::uint32_t store[2] = {0, 0};
    for_each_part(2, thread_count_ > 1 ? 2u : 1u, [&](unsigned, std::size_t begin, std::size_t end) {
      for (std::size_t h = begin; h < end; ++h) store[h] = partition_any(halves[h], split, sides[h][0], sides[h][1]);
    });
    const std::uint32_t first_right = mid - store[0], second_left = store[1] - mid;
    SahRef* refs = refs_.get();
    if (first_right <= second_left)
      std::swap_ranges(refs + store[0], refs + mid, refs + store[1] - first_right);
    else
      std::swap_ranges(refs + mid, refs + store[1], refs + store[0]);
    for (int side = 0; side < 2; ++side) {
      Range& out = side == 0 ? left : right;
      out.centres.grow(sides[0][side].centres);
      out.centres.grow(sides[1][side].centres);
      out.bounds.grow(sides[0][side].bounds);
      out.bounds.grow(sides[1][side].bounds);
    }
    return store[0] + second_left;
  }

  // Object median along the longest centroid axis: both halves non-empty.
  std::uint32_t median_split(const Range& range) {
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (range.centres.hi[a] - range.centres.lo[a] > range.centres.hi[axis] - range.centres.lo[axis]) axis = a;
    std::uint32_t mid = range.begin + (range.end - range.begin) / 2;
    std::nth_element(refs_.get() + range.begin, refs_.get() + mid, refs_.get() + range.end,
                     [axis](const SahRef& x, const SahRef& y) { return centre_of(x)[axis] < centre_of(y)[axis]; });
    return mid;
  }

  // A subtree waiting for a thread.
  struct Task {
    std::uint32_t subtree;  // index in subtrees_
    Range range;
    std::uint32_t depth;
  };

  // Builds the subtree of range into nodes[node] and new nodes appended to
  // nodes; a child of at least parallel_min_primitives references becomes a
  // subtree of its own on the task list when more than one thread builds.
  // With Children::as_tasks (the root, split before the threads take tasks)
  // both children become tasks, and build returns.
  enum class Children { built, as_tasks };
  void build(std::vector<BuildNode>& nodes, std::uint32_t node, const Range& range, std::uint32_t depth,
             Children children = Children::built) {
    const std::uint32_t n = range.end - range.begin;
    const bool root = n == ref_count_;
    const float area = range.bounds.area();
    Split split;
    if (n > 1 && depth < config_.max_sah_depth && !(n <= config_.max_leaf_size && leaf_wins_any_split(range, area)))
      split = find_split(range, root);
    if (n <= config_.max_leaf_size &&
        (split.axis < 0 || area * blocks(n) <= config_.node_cost * area + split.cost)) {
      BuildNode& leaf = nodes[node];
      leaf.bounds = range.bounds.aabb();
      leaf.first = range.begin;
      leaf.count = n;
      return;
    }
    Range left{range.begin, 0, Box::empty(), Box::empty()}, right{0, range.end, Box::empty(), Box::empty()};
    if (split.axis >= 0) {
      left.end = right.begin = root && n >= kParallelBinMin ? partition_halves(range, split, left, right)
                                                             : partition_any(range, split, left, right);
      if (!split.sampled) {
        left.bounds = split.left;
        right.bounds = split.right;
      }
    }
    // The partition recomputes the bins the counts came from, so neither side
    // is empty; should rounding ever disagree, the median split takes over.
    if (split.axis < 0 || left.end == left.begin || right.begin == right.end) {
      left.bounds = left.centres = right.bounds = right.centres = Box::empty();
      left.end = right.begin = median_split(range);
      for (std::uint32_t i = left.begin; i < left.end; ++i) {
        left.bounds.grow(box_of(refs_[i]));
        left.centres.grow_point(centre_of(refs_[i]));
      }
      for (std::uint32_t i = right.begin; i < right.end; ++i) {
        right.bounds.grow(box_of(refs_[i]));
        right.centres.grow_point(centre_of(refs_[i]));
      }
    }
    const bool left_smaller = left.end - left.begin < right.end - right.begin;
    const Range& small = left_smaller ? left : right;
    const Range& large = left_smaller ? right : left;
    const bool as_tasks = children == Children::as_tasks;
    const bool hand_off =
        as_tasks || (thread_count_ > 1 && small.end - small.begin >= config_.parallel_min_primitives);
    auto task_ref = [&](const Range& child) {
      std::lock_guard<std::mutex> lock(mutex_);
      const std::uint32_t subtree = new_subtree(child.end - child.begin);
      add_task({subtree, child, depth + 1});
      return kSubtreeRef | subtree;
    };
    std::uint32_t small_ref;
    if (hand_off) {
      small_ref = task_ref(small);
      ready_.notify_one();
    } else {
      small_ref = static_cast<std::uint32_t>(nodes.size());
      nodes.emplace_back();
    }
    std::uint32_t large_ref;
    if (as_tasks) {
      large_ref = task_ref(large);
    } else {
      large_ref = static_cast<std::uint32_t>(nodes.size());
      nodes.emplace_back();
    }
    BuildNode& inner = nodes[node];
    inner.bounds = range.bounds.aabb();
    inner.child[0] = left_smaller ? small_ref : large_ref;
    inner.child[1] = left_smaller ? large_ref : small_ref;
    if (as_tasks) return;
    if (!hand_off) build(nodes, small_ref, small, depth + 1);
    build(nodes, large_ref, large, depth + 1);
  }

  // Adds a task (the mutex held, or before the threads start).
  void add_task(const Task& task) {
    tasks_.push_back(task);
    task_count_.store(tasks_.size(), std::memory_order_relaxed);
  }

  // One thread of the build: takes subtrees from tasks_ (the largest first)
  // until none is left and no thread is building one (which could add more).
  void work() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      if (tasks_.empty() && busy_threads_ > 0) {
        lock.unlock();
        spin_until([&] {
          return task_count_.load(std::memory_order_relaxed) != 0 || busy_threads_.load(std::memory_order_relaxed) == 0;
        });
        lock.lock();
      }
      ready_.wait(lock, [&] { return !tasks_.empty() || busy_threads_ == 0; });
      if (tasks_.empty()) {
        ready_.notify_all();
        return;
      }
      auto largest = std::max_element(tasks_.begin(), tasks_.end(), [](const Task& a, const Task& b) {
        return a.range.end - a.range.begin < b.range.end - b.range.begin;
      });
      Task task = *largest;
      tasks_.erase(largest);
      task_count_.store(tasks_.size(), std::memory_order_relaxed);
      std::vector<BuildNode>* nodes = subtrees_[task.subtree].get();
      ++busy_threads_;
      lock.unlock();
      build(*nodes, 0, task.range, task.depth);
      lock.lock();
      --busy_threads_;
    }
  }

  // A subtree's nodes, root first, from an empty vector in subtrees_ (the
  // mutex held); n: its references, for the room its nodes take.
  std::uint32_t new_subtree(std::size_t n) {
    auto nodes = std::make_unique<std::vector<BuildNode>>();
    reserve_advised(*nodes, n / 2 + 1);
    nodes->emplace_back();
    subtrees_.push_back(std::move(nodes));
    return static_cast<std::uint32_t>(subtrees_.size() - 1);
  }

  // The subtrees' nodes in one array, subtree 0's first: each child index
  // rebased onto its own subtree's place, a subtree reference onto that
  // subtree's root. Subtrees are copied on whichever thread is free.
  void assemble(std::vector<BuildNode>& out) const {
    std::vector<std::uint32_t> first(subtrees_.size());
    std::size_t total = 0;
    for (std::size_t k = 0; k < subtrees_.size(); ++k) {
      first[k] = static_cast<std::uint32_t>(total);
      total += subtrees_[k]->size();
    }
    reserve_faulted(out, total, thread_count_);
    out.resize(total);
    for_each_index(subtrees_.size(), thread_count_, [&](std::size_t k) {
      BuildNode* to = out.data() + first[k];
      for (const BuildNode& n : *subtrees_[k]) {
        *to = n;
        if (!n.is_leaf())
          for (std::uint32_t& c : to->child) c = c & kSubtreeRef ? first[c & ~kSubtreeRef] : first[k] + c;
        ++to;
      }
    });
  }

  const SahConfig& config_;
  std::unique_ptr<SahRef[]> refs_;
  std::size_t ref_count_;
  Range root_;  // all of refs_
  // Each subtree built as a task has its own nodes (threads never write to
  // one array: a shared counter and shared cache lines would serialise
  // them); child indices are local to the subtree,
  // or kSubtreeRef | the index of another subtree in subtrees_. Guarded by
  // mutex_ while tasks are added.
  std::vector<std::unique_ptr<std::vector<BuildNode>>> subtrees_;
  unsigned thread_count_ = 1;
  std::mutex mutex_;
  std::condition_variable ready_;
  std::vector<Task> tasks_;     // subtrees waiting for a thread
  std::atomic<std::size_t> task_count_{0};  // tasks_.size(), read without the mutex
  std::atomic<int> busy_threads_{0};        // threads building a task (changed under mutex_)
};

}  // namespace

namespace {

void check_config(const SahConfig& config) {
  if (config.bin_count < 2 || config.bin_count > kMaxBins)
    throw Error("SAH builder: bin_count " + std::to_string(config.bin_count) + " is outside 2..256");
  if (config.max_leaf_size < 1 || config.max_leaf_size > RTCL_BLOCK_WIDTH)
    throw Error("SAH builder: max_leaf_size " + std::to_string(config.max_leaf_size) + " is outside 1..8");
  if (!(config.node_cost >= 0.0f) || !std::isfinite(config.node_cost))
    throw Error("SAH builder: node_cost must be finite and >= 0");
  if (config.max_sah_depth > 1024)
    throw Error("SAH builder: max_sah_depth " + std::to_string(config.max_sah_depth) + " is above 1024");
}

void check_refs(const std::unique_ptr<SahRef[]>& refs, std::size_t count) {
  if (count > 0x7fffffffu) throw Error("SAH builder: " + std::to_string(count) + " primitives exceed 2^31 - 1");
  if (count > 0 && !refs) throw Error("SAH builder: " + std::to_string(count) + " references and no array");
}

}  // namespace

BuildTree build_sah(std::span<const Aabb> bounds, std::span<const std::uint32_t> ids, const SahConfig& config) {
  check_config(config);
  check_builder_sizes(bounds, ids, "SAH builder");
  return SahBuilder(bounds, ids, config).run();
}

BuildTree build_sah(std::unique_ptr<SahRef[]> refs, std::size_t count, const SahConfig& config) {
  check_config(config);
  check_refs(refs, count);
  return SahBuilder(std::move(refs), count, config).run();
}

BuildTree build_sah(std::unique_ptr<SahRef[]> refs, std::size_t count, const SahBounds& bounds,
                    const SahConfig& config) {
  check_config(config);
  check_refs(refs, count);
  return SahBuilder(std::move(refs), count, bounds, config).run();
}

}  // namespace rtcl
