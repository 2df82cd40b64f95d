// Uniform grid (lecture: 均匀格点, Uniform Grids): a 3D array of cells over the
// scene box, each listing the primitives that overlap it, stored compactly
// (per-cell offsets plus one reference array, Lagae & Dutre 2008) and walked
// by a 3D-DDA (Amanatides & Woo 1987) in kernels/accel/grid.cl, which skips
// empty space by occupied-space boxes and macrocells.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/accel/structure_kernels.hpp"
#include "rtcl/accel/primitive_blocks.hpp"
#include "rtcl/layouts.hpp"

namespace rtcl {

// Cells per axis (x, y, z), each >= 1; {0, 0, 0} means "from the density".
using GridResolution = std::array<std::uint32_t, 3>;

struct GridConfig {
  // Density: about lambda * N cells for N stored primitives, split in
  // proportion to the box's sides (Cleary & Wyvill 1988; Wald et al. 2006).
  // The lecture's trade-off: fewer cells make long lists, more make many
  // empty cells to walk and more memory. Time per ray is U-shaped in the
  // cell count and flat over a wide range around the default 8 (the sweep:
  // docs/benchmarks.md); a reference lane costs 40 bytes.
  double lambda = 8.0;
  // Reference budget of an automatic resolution: when a sample of the
  // triangles meets more cells than this on average, lambda is divided by 4
  // until it does not. Long slivers across the grid would otherwise be listed
  // in hundreds of cells each (a fan of thin triangles around one vertex:
  // hundreds of references per triangle, gigabytes of lists). Real meshes
  // stay far below it, at a few references per triangle.
  double max_references_per_triangle = 64.0;
  // Explicit resolution; overrides lambda (and the budget) when not {0, 0, 0}.
  GridResolution resolution{0, 0, 0};
  // Side of a macrocell in cells, a power of two in [1, 256]: the walk
  // crosses an empty macrocell in one step (empty-space skipping); 1 makes
  // every empty cell its own macrocell. 4 and 8 trace alike on the
  // shared meshes, 2 and 1 slower (docs/benchmarks.md).
  unsigned macro = 4;
  // Host threads for the overlap pass (0 = 2); the pass splits the
  // triangles into this many contiguous ranges.
  unsigned thread_count = 0;
  // The largest buffer the device can allocate (0: no limit); a grid whose
  // cell offsets or reference list would exceed it is refused before the
  // overlap pass, or as soon as the count is known.
  std::size_t max_alloc_bytes = 0;
  // Occlusion: consecutive rays per work-item, each tested first against
  // the cell whose triangles blocked the previous one; 1 = no such test,
  // 0 = by device (occluder_run_for, accel.hpp).
  std::uint32_t occluder_run = 0;
};

// The host image of what the kernel reads (kernels/shared/layouts.h).
struct Grid {
  GridHeader header{};
  std::vector<rtcl_u32> cell_begin;  // cells + 1 offsets into refs
  std::vector<rtcl_i32> refs;        // per cell: triangle refs k >= 0, then sphere refs ~j
  std::vector<std::uint8_t> occupied;  // per macrocell: 1 when one of its cells has a reference
  std::vector<float> occupied_boxes;   // per octant o: rows [6][8] of its sub-octants' occupied boxes
  std::vector<float> lanes;            // 9 rows of header.lane_stride: the triangle of each reference
  std::vector<rtcl_i32> lane_prims;    // header.lane_stride: its primitive id, -1 for none
  PrimitiveBlocks blocks;            // stored primitives in id order (in_order_blocks)
  std::size_t cell_count() const { return cell_begin.empty() ? 0 : cell_begin.size() - 1; }
  // Everything the device holds: header, cell offsets, macrocells, reference
  // lanes, and for scenes with spheres the references and sphere blocks.
  std::size_t bytes() const;
};

// The density heuristic: cells ~ lambda * primitives, r_a proportional to
// extent[a]; an axis of (near) zero extent gets 1 cell and the others share
// the budget. Each axis is clamped to [1, 65536].
GridResolution grid_resolution(const glm::dvec3& extent, std::size_t primitives, double lambda);

// Builds the grid over the stored primitives of validated geometry. Throws
// Error naming the option (lambda, res) for a bad config, and the limit for
// a grid larger than config.max_alloc_bytes allows.
Grid build_grid(const Geometry& geometry, const GridConfig& config = {});

// Its registry entry: lambda (GridConfig::lambda), res
// (GridConfig::resolution, "auto" = from lambda) and macro
// (GridConfig::macro).
const StructureSpec& grid_structure();

// The registered factory: make_grid configured by config.options.
std::unique_ptr<Accel> make_grid_accel(const Device& device, const Geometry& geometry, const AccelConfig& config);

// Builds and uploads; stats().build_ms covers build_grid.
std::unique_ptr<Accel> make_grid(const Device& device, const Geometry& geometry, const GridConfig& config = {},
                                 const AccelConfig& accel_config = {});

}  // namespace rtcl
