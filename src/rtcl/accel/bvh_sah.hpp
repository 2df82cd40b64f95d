// Top-down binned SAH builder (Wald 2007, "On fast construction of SAH-based
// bounding volume hierarchies"): at each node, primitive centroids are binned
// along all three axes and the plane between two bins with the lowest surface
// area cost is taken. Leaves hold up to eight primitives: one block that the
// kernel tests in float8 lanes.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>

#include "rtcl/accel/build_tree.hpp"

namespace rtcl {

struct SahConfig {
  // Bins per axis (2..256) at nodes of at least 8 * bin_count primitives;
  // smaller nodes use n / 8 bins, but at least min(8, bin_count): a node
  // costs O(n + bins), and the plane choice matters most near the root. More
  // bins find better planes where primitive density is uneven (sponza), at
  // a build cost linear in the bins; 32 is where that gain levels off. The
  // n / 8 rule below the top keeps small nodes cheap at an SAH cost within
  // a percent of finer binning (figures: docs/benchmarks.md).
  std::uint32_t bin_count = 32;
  // A node of at least twice this many primitives bins every k-th one only,
  // k = n / binning_samples rounded down and made odd (an odd stride does
  // not fall in step with a mesh's power-of-two rows): at least this many
  // samples choose its plane, and the partition then computes both sides'
  // exact boxes. The binning pass of the large nodes near the root, whose
  // references stream from memory, drops out of the build time, at an SAH
  // cost within 0.1% of binning all on the meshes measured
  // (docs/benchmarks.md). 0: every node bins every primitive.
  std::uint32_t binning_samples = 65536;
  // Cost of entering one binary node relative to testing one block of eight
  // primitives. Higher makes shallower trees with fuller leaves, lower splits
  // more eagerly. With leaves charged ceil(n / 8) blocks they fill anyway
  // (most of their 8 lanes), so values from 0.25 to 2 change bytes and
  // trace speed little.
  float node_cost = 0.5f;
  // Largest leaf (1..8). The SAH charges a leaf ceil(n / 8) block tests, so
  // leaves tend to fill the eight lanes; a smaller cap only adds nodes.
  std::uint32_t max_leaf_size = 8;
  // Deeper than this, nodes are split at the object median along the longest
  // centroid axis instead of by SAH: the tree depth, and with it the
  // traversal stack, stays below max_sah_depth + log2(n) even for adversarial
  // inputs, at some loss of quality there. At most 1024.
  std::uint32_t max_sah_depth = 48;
  // With more than one thread, each subtree of at least this many
  // primitives is a task of its own (a thread that waits for work takes the
  // largest waiting one), and a root of at least 16384 primitives is binned
  // by the threads together and partitioned in two halves; thread_count
  // bounds the threads in use (0 = all hardware threads). The tree does not
  // depend on the threads.
  std::size_t parallel_min_primitives = 2048;
  unsigned thread_count = 0;
};

// Builds over primitives whose boxes are bounds[i] and ids are ids[i]; the
// leaves hold those ids. Throws Error for mismatched spans, a box with a NaN
// or infinite coordinate or lower > upper, or an invalid config.
BuildTree build_sah(std::span<const Aabb> bounds, std::span<const std::uint32_t> ids, const SahConfig& config = {});

// One primitive as the SAH builder holds it, 32 bytes: its box's lower and
// upper corners, lower[3] zero and upper[3] the id's bits.
struct alignas(16) SahRef {
  float lower[4];
  float upper[4];

  static SahRef of(const Aabb& box, std::uint32_t id) {
    return {{box.lower.x, box.lower.y, box.lower.z, 0.0f},
            {box.upper.x, box.upper.y, box.upper.z, std::bit_cast<float>(id)}};
  }
};

// Builds over refs[0, count), which a caller filled in its own pass over
// the primitives (SahRef::of), without a copy of them into the builder's
// array; the same tree as from the boxes and ids, the same errors.
BuildTree build_sah(std::unique_ptr<SahRef[]> refs, std::size_t count, const SahConfig& config = {});

// The union of references' boxes and that of their centres (0.5 lower +
// 0.5 upper per axis, the builder's arithmetic), gathered by a caller that
// fills the references.
struct SahBounds {
  Aabb boxes, centres;

  void add(const SahRef& r) {
    const glm::vec3 lower(r.lower[0], r.lower[1], r.lower[2]), upper(r.upper[0], r.upper[1], r.upper[2]);
    boxes.grow(Aabb{lower, upper});
    centres.grow(0.5f * lower + 0.5f * upper);
  }
  void add(const SahBounds& b) {
    boxes.grow(b.boxes);
    centres.grow(b.centres);
  }
};

// As above, over refs whose boxes the caller knows to be valid (finite,
// lower <= upper: a triangle's of validated vertices) and whose bounds it
// gathered while filling them: the builder skips its own pass over them.
// The same tree.
BuildTree build_sah(std::unique_ptr<SahRef[]> refs, std::size_t count, const SahBounds& bounds,
                    const SahConfig& config = {});

}  // namespace rtcl
