// Bottom-up (agglomerative) builder: Parallel Locally-Ordered Clustering
// (Meister & Bittner 2018, "Parallel Locally-Ordered Clustering for Bounding
// Volume Hierarchy Construction", IEEE TVCG 24(3)). As the lecture puts it,
// the hierarchy is built bottom-up from each object's bounding volume: every
// primitive starts as a cluster, clusters are kept in Morton order of their
// centroids, and each round every cluster finds its nearest neighbour among
// the `search_radius` clusters on either side (distance = surface area of the
// union of the two boxes); mutual nearest neighbours merge into a parent.
// Subtrees of up to eight primitives then become leaves where the SAH says a
// leaf is cheaper.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "rtcl/accel/build_tree.hpp"

namespace rtcl {

struct PlocConfig {
  // Clusters searched on each side in Morton order (the paper's r, 1..1024).
  // Larger finds closer partners (better trees) at a build cost linear in r;
  // past 16 the trees gain little. 16 is the paper's recommendation
  // (Meister & Bittner 2018).
  std::uint32_t search_radius = 16;
  // Leaf formation: cost of entering one binary node relative to testing one
  // block of eight primitives (as SahConfig::node_cost).
  float node_cost = 0.5f;
  // Largest leaf (1..8).
  std::uint32_t max_leaf_size = 8;
  // Subtrees that reach this depth are rebuilt by object-median splits, so
  // that the depth (and the traversal stack) stays below max_depth + log2(n)
  // even for inputs that make clustering form chains (nested boxes).
  std::uint32_t max_depth = 64;
  // Threads for the neighbour search (0 = all hardware threads); rounds with
  // fewer than parallel_min_clusters clusters run on one thread.
  unsigned thread_count = 0;
  std::size_t parallel_min_clusters = 4096;
};

// Builds over primitives whose boxes are bounds[i] and ids are ids[i]; the
// leaves hold those ids. Throws Error for mismatched spans, a box with a NaN
// or infinite coordinate or lower > upper, or an invalid config.
BuildTree build_ploc(std::span<const Aabb> bounds, std::span<const std::uint32_t> ids,
                     const PlocConfig& config = {});

}  // namespace rtcl
