#include "rtcl/accel/grid.hpp"
#include "rtcl/accel/structure_kernels.hpp"

#include <algorithm>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "rtcl/bounds/overlap.hpp"
#include "rtcl/error.hpp"
#include "rtcl/thread_pool.hpp"

namespace rtcl {

namespace {

constexpr double kMaxAxisCells = 65536.0;
// Cell indices are int on the device: cells < 2^31.
constexpr std::uint64_t kMaxCells = 0x7fffffffu;
constexpr unsigned kMaxMacro = 256;
// Positions past the last reference lane: a float8 run starting at the last
// reference stays inside its row.
constexpr std::size_t kLanePadding = RTCL_BLOCK_WIDTH;
// The kernel indexes a lane row as row * lane_stride in int (triangle.h,
// intersect_triangle_run): the 9 rows of lane_stride floats stay below 2^31
// whatever the device's largest buffer.
constexpr std::size_t kMaxLaneRefs = 0x7fffffffu / 9 - kLanePadding;

std::string resolution_text(const GridResolution& r) {
  return std::to_string(r[0]) + "x" + std::to_string(r[1]) + "x" + std::to_string(r[2]);
}

// The float coordinate of cell plane n on axis a, exactly as the kernel
// computes it (GridHeader contract).
float plane(const GridHeader& g, int a, std::int64_t n) { return g.lower[a] + static_cast<float>(n) * g.cell[a]; }

// Where the build works: the header, and the widening of every cell box for
// the overlap tests. The widening (64 float ulps of the scene's magnitude)
// covers the rounding of the kernel's cell planes, slab distances and hit
// points, so that a primitive touching or nearly touching a cell boundary is
// listed in the cells on both sides.
struct Frame {
  GridHeader header{};
  double widen = 0.0;

  // Cells [lo, hi] on axis a whose widened slabs meet [x0, x1].
  void range(int a, double x0, double x1, std::int64_t* lo, std::int64_t* hi) const {
    std::int64_t last = header.res[a] - 1;
    auto index = [&](double x) {
      double f = std::floor((x - header.lower[a]) / header.cell[a]);
      return static_cast<std::int64_t>(std::clamp(f, 0.0, static_cast<double>(last)));
    };
    *lo = index(x0 - widen);
    *hi = index(x1 + widen);
    // The division above may round across a plane: settle on the planes.
    while (*lo > 0 && plane(header, a, *lo) + widen >= x0) --*lo;
    while (*lo < last && plane(header, a, *lo + 1) + widen < x0) ++*lo;
    while (*hi < last && plane(header, a, *hi + 1) - widen <= x1) ++*hi;
    while (*hi > *lo && plane(header, a, *hi) - widen > x1) --*hi;
  }
  glm::dvec3 cell_lower(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return glm::dvec3(plane(header, 0, i), plane(header, 1, j), plane(header, 2, k)) - widen;
  }
  glm::dvec3 cell_upper(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return glm::dvec3(plane(header, 0, i + 1), plane(header, 1, j + 1), plane(header, 2, k + 1)) + widen;
  }
  std::uint32_t cell_index(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return static_cast<std::uint32_t>(i + header.res[0] * (j + static_cast<std::int64_t>(header.res[1]) * k));
  }
};

struct CellRef {
  std::uint32_t cell;
  rtcl_i32 ref;
};

// The x extent of triangle `tri` clipped to the slab y0 <= y <= y1,
// z0 <= z <= z1 (Sutherland-Hodgman, in double); false when nothing is left.
bool clipped_x_extent(const glm::dvec3* tri, double y0, double y1, double z0, double z1, double* x0, double* x1) {
  glm::dvec3 poly[16], next[16];
  int n = 3;
  for (int v = 0; v < 3; ++v) poly[v] = tri[v];
  const struct {
    int axis;
    double bound, sign;  // keep sign * (p[axis] - bound) >= 0
  } planes[4] = {{1, y0, 1.0}, {1, y1, -1.0}, {2, z0, 1.0}, {2, z1, -1.0}};
  for (const auto& pl : planes) {
    int m = 0;
    for (int v = 0; v < n; ++v) {
      const glm::dvec3 &p = poly[v], &q = poly[(v + 1) % n];
      double dp = pl.sign * (p[pl.axis] - pl.bound), dq = pl.sign * (q[pl.axis] - pl.bound);
      if (dp >= 0) next[m++] = p;
      if ((dp >= 0) != (dq >= 0)) next[m++] = p + (q - p) * (dp / (dp - dq));
    }
    n = m;
    if (n == 0) return false;
    for (int v = 0; v < n; ++v) poly[v] = next[v];
  }
  *x0 = *x1 = poly[0].x;
  for (int v = 1; v < n; ++v) {
    *x0 = std::min(*x0, poly[v].x);
    *x1 = std::max(*x1, poly[v].x);
  }
  return true;
}

// Appends (cell, ref) for every cell the primitive with this box overlaps;
// `overlaps(lower, upper)` decides cells of boxes that the box alone cannot.
// For a triangle (`tri` its vertices), each row of cells along x is first
// narrowed to the x extent of the triangle clipped to the row's widened
// slab, so that the exact tests run on about as many cells as the triangle
// meets, not on its whole box (a long sliver across the grid would test
// every cell of its box: the fan of tests/precision_test.cpp).
template <class Overlaps>
void emit(const Frame& f, const glm::dvec3& lower, const glm::dvec3& upper, rtcl_i32 ref, bool test_always,
          const Overlaps& overlaps, std::vector<CellRef>& out, const glm::dvec3* tri = nullptr) {
  std::int64_t lo[3], hi[3];
  for (int a = 0; a < 3; ++a) f.range(a, lower[a], upper[a], &lo[a], &hi[a]);
  // A convex primitive whose box lies within one slab on two axes meets
  // every cell of its range along the third: no test needed.
  int spanning = (hi[0] > lo[0]) + (hi[1] > lo[1]) + (hi[2] > lo[2]);
  bool test = test_always || spanning >= 2;
  for (std::int64_t k = lo[2]; k <= hi[2]; ++k)
    for (std::int64_t j = lo[1]; j <= hi[1]; ++j) {
      std::int64_t i0 = lo[0], i1 = hi[0];
      if (tri && test && hi[0] - lo[0] > 2) {
        glm::dvec3 cl = f.cell_lower(0, j, k), cu = f.cell_upper(0, j, k);
        double x0, x1;
        if (!clipped_x_extent(tri, cl.y, cu.y, cl.z, cu.z, &x0, &x1)) continue;
        std::int64_t r0, r1;
        f.range(0, x0, x1, &r0, &r1);
        i0 = std::max(i0, r0);
        i1 = std::min(i1, r1);
      }
      for (std::int64_t i = i0; i <= i1; ++i)
        if (!test || overlaps(f.cell_lower(i, j, k), f.cell_upper(i, j, k))) out.push_back({f.cell_index(i, j, k), ref});
    }
}

// Appends (cell, ref) for every cell geometry's triangle `id` overlaps
// (exact test in double).
void emit_triangle(const Frame& f, const Geometry& geometry, std::uint32_t id, rtcl_i32 ref,
                   std::vector<CellRef>& out) {
  const glm::uvec3& t = geometry.triangles[id];
  glm::dvec3 a(geometry.vertices[t.x]), b(geometry.vertices[t.y]), c(geometry.vertices[t.z]);
  const glm::dvec3 tri[3] = {a, b, c};
  emit(f, glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c)), ref, false,
       [&](const glm::dvec3& lo, const glm::dvec3& hi) {
         return triangle_box_overlap(a, b, c, 0.5 * (lo + hi), 0.5 * (hi - lo));
       },
       out, tri);
}

// Mean cell references per triangle of frame f over an evenly spaced
// sample of at most `samples` of the first `triangle_count` stored
// primitives (the exact overlap pass on the sample).
double sampled_references_per_triangle(const Frame& f, const Geometry& geometry, const std::vector<std::uint32_t>& ids,
                                       std::size_t triangle_count, std::size_t samples) {
  std::size_t step = std::max<std::size_t>(1, triangle_count / samples), taken = 0;
  std::vector<CellRef> out;
  for (std::size_t k = 0; k < triangle_count; k += step, ++taken) {
    emit_triangle(f, geometry, ids[k], 0, out);
  }
  return taken ? static_cast<double>(out.size()) / static_cast<double>(taken) : 0.0;
}

[[noreturn]] void too_large(const Geometry& g, const std::string& option, const std::string& what, std::uint64_t bytes,
                            std::size_t limit) {
  throw Error("grid over " + g.source + ": " + option + ": " + what + " need " + std::to_string(bytes) +
              " bytes, more than the device's largest buffer (" + std::to_string(limit) +
              " bytes, CL_DEVICE_MAX_MEM_ALLOC_SIZE); use a smaller lambda or res");
}

// `lambda`: the density used when config.resolution is automatic (the
// configured one, or less when the reference budget shrinks it).
Frame make_frame(const Geometry& geometry, const GridConfig& config, double lambda, std::size_t primitives,
                 std::string* option) {
  if (!(config.lambda > 0.0) || !std::isfinite(config.lambda))
    throw Error("grid: lambda must be > 0 (got " + std::to_string(config.lambda) + ")");
  bool explicit_res = config.resolution != GridResolution{0, 0, 0};
  for (std::uint32_t r : config.resolution)
    if (explicit_res && (r < 1 || r > kMaxAxisCells))
      throw Error("grid: res=" + resolution_text(config.resolution) + ": every axis must be in [1, 65536]");
  *option = explicit_res ? "res=" + resolution_text(config.resolution) : "lambda=" + std::to_string(config.lambda);
  if (config.macro < 1 || config.macro > kMaxMacro || (config.macro & (config.macro - 1)) != 0)
    throw Error("grid: macro must be a power of two in [1, " + std::to_string(kMaxMacro) + "] (got " +
                std::to_string(config.macro) + ")");

  Aabb box = geometry.bounds();
  glm::dvec3 lower(box.lower), upper(box.upper);
  double magnitude = 0.0;
  for (int a = 0; a < 3; ++a) magnitude = std::max({magnitude, std::fabs(lower[a]), std::fabs(upper[a])});
  double pad = std::max(16.0 * FLT_EPSILON * magnitude, static_cast<double>(FLT_MIN));
  Frame f;
  f.widen = 64.0 * FLT_EPSILON * magnitude + static_cast<double>(FLT_MIN);
  GridResolution res = explicit_res ? config.resolution : grid_resolution(upper - lower, primitives, lambda);
  std::uint64_t cells = std::uint64_t(res[0]) * res[1] * res[2];
  if (cells > kMaxCells)
    throw Error("grid over " + geometry.source + ": " + *option + ": " + resolution_text(res) + " = " +
                std::to_string(cells) + " cells, more than the 2^31-1 the kernel can index");
  if (config.max_alloc_bytes && (cells + 1) * sizeof(rtcl_u32) > config.max_alloc_bytes)
    too_large(geometry, *option, resolution_text(res) + " cell offsets", (cells + 1) * sizeof(rtcl_u32),
              config.max_alloc_bytes);
  for (int a = 0; a < 3; ++a) {
    // Rounded outwards: the grid box contains the padded scene box.
    float lo = std::nextafter(static_cast<float>(lower[a] - pad), -std::numeric_limits<float>::infinity());
    double hi = upper[a] + pad;
    float cell = std::nextafter(static_cast<float>((hi - lo) / res[a]), std::numeric_limits<float>::infinity());
    f.header.lower[a] = lo;
    f.header.res[a] = static_cast<rtcl_i32>(res[a]);
    f.header.cell[a] = cell;
    while (plane(f.header, a, res[a]) < hi) f.header.cell[a] = std::nextafter(f.header.cell[a], FLT_MAX);
  }
  int shift = 0;
  while ((1u << shift) < config.macro) ++shift;
  f.header.macro[3] = shift;
  for (int a = 0; a < 3; ++a) f.header.macro[a] = ((f.header.res[a] - 1) >> shift) + 1;
  return f;
}

}  // namespace

std::size_t Grid::bytes() const {
  std::size_t spheres = blocks.spheres.empty() ? 0
                                               : refs.size() * sizeof(rtcl_i32) + blocks.spheres.size() * sizeof(SphereBlock);
  return sizeof(GridHeader) + cell_begin.size() * sizeof(rtcl_u32) + occupied.size() +
         occupied_boxes.size() * sizeof(float) + lanes.size() * sizeof(float) +
         lane_prims.size() * sizeof(rtcl_i32) + spheres;
}

GridResolution grid_resolution(const glm::dvec3& extent, std::size_t primitives, double lambda) {
  // r_a = extent_a * k with prod(r_a) = lambda * N over the axes still
  // free; an axis that would get less than one cell gets one and leaves
  // the budget to the others.
  double target = std::max(1.0, lambda * static_cast<double>(primitives));
  bool free_axis[3] = {extent.x > 0.0, extent.y > 0.0, extent.z > 0.0};
  GridResolution res{1, 1, 1};
  for (int round = 0; round < 3; ++round) {
    double volume = 1.0;
    int dims = 0;
    for (int a = 0; a < 3; ++a)
      if (free_axis[a]) volume *= extent[a], ++dims;
    if (dims == 0) break;
    double k = std::pow(target / volume, 1.0 / dims);
    bool changed = false;
    for (int a = 0; a < 3; ++a) {
      if (!free_axis[a]) continue;
      double r = extent[a] * k;
      if (r < 1.0) {
        free_axis[a] = false;
        res[a] = 1;
        changed = true;
      } else {
        res[a] = static_cast<std::uint32_t>(std::min(kMaxAxisCells, std::max(1.0, std::round(r))));
      }
    }
    if (!changed) break;
  }
  return res;
}

Grid build_grid(const Geometry& geometry, const GridConfig& config) {
  std::vector<std::uint32_t> ids = stored_primitives(geometry);
  std::string option;
  std::size_t triangle_count = ids.size() - geometry.spheres.size();
  double lambda = config.lambda;
  Frame f = make_frame(geometry, config, lambda, ids.size(), &option);
  // The reference budget (GridConfig::max_references_per_triangle): an
  // automatic resolution is coarsened, 4x fewer cells per round, until a
  // sample of the triangles stays within it.
  bool automatic = config.resolution == GridResolution{0, 0, 0};
  for (int round = 0; automatic && round < 16 &&
                      sampled_references_per_triangle(f, geometry, ids, triangle_count, 1024) >
                          config.max_references_per_triangle;
       ++round) {
    lambda *= 0.25;
    f = make_frame(geometry, config, lambda, ids.size(), &option);
  }
  // The largest buffer is the reference lanes: 9 floats per reference.
  std::size_t max_refs = config.max_alloc_bytes ? config.max_alloc_bytes / (9 * sizeof(float)) : kMaxCells;
  max_refs = max_refs > kLanePadding ? max_refs - kLanePadding : 0;
  max_refs = std::min<std::size_t>(max_refs, kMaxCells);
  const bool index_bound = max_refs > kMaxLaneRefs;
  max_refs = std::min(max_refs, kMaxLaneRefs);

  // Pass 1 (parallel over contiguous triangle ranges): (cell, ref) pairs.
  unsigned threads = config.thread_count ? config.thread_count : 2;
  if (triangle_count < 4096) threads = 1;
  std::vector<std::vector<CellRef>> parts(threads + 1);
  std::vector<char> overflow(threads + 1, 0);
  auto triangles = [&](unsigned part) {
    std::size_t begin = triangle_count * part / threads, end = triangle_count * (part + 1) / threads;
    std::vector<CellRef>& out = parts[part];
    out.reserve((end - begin) * 4);
    for (std::size_t k = begin; k < end; ++k) {
      emit_triangle(f, geometry, ids[k], static_cast<rtcl_i32>(k), out);
      if (out.size() > max_refs) {
        overflow[part] = 1;
        return;
      }
    }
  };
  run_jobs(threads, triangles);
  for (std::size_t j = 0; j < geometry.spheres.size(); ++j) {
    const Sphere& s = geometry.spheres[j];
    glm::dvec3 center(s.center);
    double r = s.radius;
    emit(f, center - r, center + r, ~static_cast<rtcl_i32>(j), true,
         [&](const glm::dvec3& lo, const glm::dvec3& hi) { return sphere_box_overlap(center, r, lo, hi); },
         parts[threads]);
  }
  std::size_t ref_count = 0;
  for (const auto& p : parts) ref_count += p.size();
  const bool overflowed = ref_count > max_refs || std::find(overflow.begin(), overflow.end(), 1) != overflow.end();
  if (overflowed && index_bound)
    throw Error("grid over " + geometry.source + ": " + option + ": more than " + std::to_string(max_refs) +
                " cell references, more than the reference lanes' 32-bit indices hold; use a smaller lambda or res");
  if (overflowed)
    too_large(geometry, option, "more than " + std::to_string(max_refs) + " cell references (9 floats each)",
              std::uint64_t(max_refs + 1 + kLanePadding) * 9 * sizeof(float),
              (max_refs + kLanePadding) * 9 * sizeof(float));

  // Pass 2: counting sort by cell, stable (triangles, in id order, before
  // spheres in every cell).
  Grid grid;
  grid.header = f.header;
  std::size_t cells = std::size_t(f.header.res[0]) * f.header.res[1] * f.header.res[2];
  grid.cell_begin.assign(cells + 1, 0);
  for (const auto& p : parts)
    for (const CellRef& r : p) ++grid.cell_begin[r.cell + 1];
  for (std::size_t c = 0; c < cells; ++c) grid.cell_begin[c + 1] += grid.cell_begin[c];
  grid.refs.resize(ref_count);
  std::vector<rtcl_u32> next(grid.cell_begin.begin(), grid.cell_begin.end() - 1);
  for (const auto& p : parts)
    for (const CellRef& r : p) grid.refs[next[r.cell]++] = r.ref;
  GridHeader& h = grid.header;
  const int shift = h.macro[3];
  grid.occupied.assign(std::size_t(h.macro[0]) * h.macro[1] * h.macro[2], 0);
  // Occupied space, two levels: the octants of the grid (split at cell
  // res / 2 per axis), and the octants of each octant (split at the middle
  // cell of its range); each box spans its cells that have references.
  std::int64_t lo[64][3], hi[64][3];
  for (int o = 0; o < 64; ++o)
    for (int a = 0; a < 3; ++a) lo[o][a] = std::numeric_limits<std::int64_t>::max(), hi[o][a] = -1;
  for (std::int64_t k = 0, c = 0; k < h.res[2]; ++k)
    for (std::int64_t j = 0; j < h.res[1]; ++j)
      for (std::int64_t i = 0; i < h.res[0]; ++i, ++c) {
        if (grid.cell_begin[c + 1] == grid.cell_begin[c]) continue;
        grid.occupied[(i >> shift) + h.macro[0] * ((j >> shift) + std::int64_t(h.macro[1]) * (k >> shift))] = 1;
        const std::int64_t at[3] = {i, j, k};
        int octant = 0, sub = 0;
        for (int a = 0; a < 3; ++a) {
          std::int64_t half = h.res[a] / 2;
          bool upper = at[a] >= half;
          std::int64_t mid = upper ? half + (h.res[a] - half) / 2 : half / 2;
          octant |= (upper ? 1 : 0) << a;
          sub |= (at[a] >= mid ? 1 : 0) << a;
        }
        const int box = octant * 8 + sub;
        for (int a = 0; a < 3; ++a) lo[box][a] = std::min(lo[box][a], at[a]), hi[box][a] = std::max(hi[box][a], at[a]);
      }
  auto set_box = [&](float* rows, int lane, const std::int64_t* l, const std::int64_t* u) {
    for (int a = 0; a < 3; ++a) {
      bool empty = u[a] < 0;
      rows[a * RTCL_BLOCK_WIDTH + lane] = empty ? std::numeric_limits<float>::infinity() : plane(h, a, l[a]);
      rows[(3 + a) * RTCL_BLOCK_WIDTH + lane] = empty ? -std::numeric_limits<float>::infinity() : plane(h, a, u[a] + 1);
    }
  };
  grid.occupied_boxes.assign(8 * 6 * RTCL_BLOCK_WIDTH, 0.0f);
  for (int o = 0; o < 8; ++o) {
    std::int64_t ol[3], ou[3];
    for (int a = 0; a < 3; ++a) ol[a] = std::numeric_limits<std::int64_t>::max(), ou[a] = -1;
    for (int sub = 0; sub < 8; ++sub) {
      set_box(&grid.occupied_boxes[o * 6 * RTCL_BLOCK_WIDTH], sub, lo[o * 8 + sub], hi[o * 8 + sub]);
      for (int a = 0; a < 3; ++a)
        if (hi[o * 8 + sub][a] >= 0) ol[a] = std::min(ol[a], lo[o * 8 + sub][a]), ou[a] = std::max(ou[a], hi[o * 8 + sub][a]);
    }
    set_box(&h.occupied_bounds[0][0], o, ol, ou);
  }
  grid.blocks = in_order_blocks(geometry, ids);
  const std::size_t stride = grid.refs.size() + kLanePadding;
  grid.header.lane_stride = static_cast<rtcl_i32>(stride);
  grid.lanes.assign(9 * stride, std::numeric_limits<float>::quiet_NaN());
  grid.lane_prims.assign(stride, -1);
  for (std::size_t k = 0; k < grid.refs.size(); ++k) {
    rtcl_i32 r = grid.refs[k];
    if (r < 0) continue;
    const TriangleBlock& b = grid.blocks.triangles[static_cast<std::size_t>(r) >> 3];
    for (int v = 0; v < 3; ++v)
      for (int a = 0; a < 3; ++a) grid.lanes[(3 * v + a) * stride + k] = b.v[v][a][r & 7];
    grid.lane_prims[k] = b.prim[r & 7];
  }
  return grid;
}

namespace {

class GridAccel final : public Accel {
 public:
  GridAccel(const Device& device, const Geometry& geometry, const Grid& grid, std::uint32_t occluder_run,
            AccelStats stats, const AccelConfig& config)
      : Accel(device, "grid", {"accel/grid.cl", 1, occluder_run_for(occluder_run, device.info())}, std::nullopt,
              primitive_defines(geometry), stats, config),
        header_(device.upload(&grid.header, sizeof grid.header, "grid header")),
        cell_begin_(device.upload(grid.cell_begin.data(), grid.cell_begin.size() * sizeof(rtcl_u32),
                                  "grid cell offsets")),
        refs_(grid.refs.empty() || grid.blocks.spheres.empty()
                  ? device.upload(&kNoRef, sizeof kNoRef, "grid references")
                  : device.upload(grid.refs.data(), grid.refs.size() * sizeof(rtcl_i32), "grid references")),
        occupied_(device.upload(grid.occupied.data(), grid.occupied.size(), "grid macrocell occupancy")),
        occupied_boxes_(device.upload(grid.occupied_boxes.data(), grid.occupied_boxes.size() * sizeof(float),
                                      "grid occupied-space boxes")),
        lanes_(device.upload(grid.lanes.data(), grid.lanes.size() * sizeof(float), "grid reference lanes")),
        lane_prims_(device.upload(grid.lane_prims.data(), grid.lane_prims.size() * sizeof(rtcl_i32),
                                  "grid reference primitive ids")),
        spheres_(grid.blocks.spheres.empty()
                     ? device.upload(&kNoSphere, sizeof kNoSphere, "grid spheres")
                     : device.upload(grid.blocks.spheres.data(), grid.blocks.spheres.size() * sizeof(SphereBlock),
                                     "grid spheres")) {}

 private:
  static constexpr rtcl_i32 kNoRef = 0;
  static constexpr SphereBlock kNoSphere{};

  void set_structure_args(cl::Kernel& kernel, cl_uint first) const override {
    kernel.setArg(first, header_);
    kernel.setArg(first + 1, cell_begin_);
    kernel.setArg(first + 2, refs_);
    kernel.setArg(first + 3, occupied_);
    kernel.setArg(first + 4, occupied_boxes_);
    kernel.setArg(first + 5, lanes_);
    kernel.setArg(first + 6, lane_prims_);
    kernel.setArg(first + 7, spheres_);
  }

  cl::Buffer header_, cell_begin_, refs_, occupied_, occupied_boxes_, lanes_, lane_prims_, spheres_;
};

}  // namespace

std::unique_ptr<Accel> make_grid(const Device& device, const Geometry& geometry, const GridConfig& config,
                                 const AccelConfig& accel_config) {
  auto start = std::chrono::steady_clock::now();
  GeometryReport report = validate(geometry);
  GridConfig limited = config;
  if (!limited.max_alloc_bytes) limited.max_alloc_bytes = device.info().max_alloc_bytes;
  Grid grid = build_grid(geometry, limited);
  AccelStats stats;
  stats.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  stats.device_bytes = grid.bytes();
  stats.primitive_count = geometry.primitive_count() - report.zero_area_triangles;
  stats.zero_area_skipped = report.zero_area_triangles;
  stats.bounds = geometry.bounds();
  stats.node_count = grid.cell_count();
  stats.leaf_count = grid.blocks.triangles.size() + grid.blocks.spheres.size();
  return std::make_unique<GridAccel>(device, geometry, grid, config.occluder_run, stats, accel_config);
}

const StructureSpec& grid_structure() {
  static const StructureSpec spec{
      "grid", "uniform grid, 3D-DDA traversal (Amanatides & Woo), exact triangle/cell overlap",
      {{"lambda", OptionType::real, GridConfig{}.lambda, 0, 1024, true,
        "cells per primitive (cells ~ lambda * N, split in proportion to the box): fewer cells make long cell "
        "lists, more make many empty cells to walk and 4 bytes of offsets per cell"},
       {"res", OptionType::resolution, GridResolution{0, 0, 0}, 1, 65536, false,
        "explicit cells per axis AxBxC, overriding lambda; auto: from lambda"},
       {"macro", OptionType::integer, static_cast<std::int64_t>(GridConfig{}.macro), 1, kMaxMacro, false,
        "macrocell side in cells: the walk crosses an empty macrocell in one step; 1: cell by cell",
        true},
       occluder_run_option()}};
  return spec;
}

std::unique_ptr<Accel> make_grid_accel(const Device& device, const Geometry& geometry, const AccelConfig& config) {
  const AccelOptions& o = config.options;
  GridConfig grid;
  grid.lambda = o.real("lambda");
  grid.resolution = o.resolution("res");
  grid.macro = static_cast<unsigned>(o.integer("macro"));
  grid.occluder_run = static_cast<std::uint32_t>(o.integer("occluder_run"));
  return make_grid(device, geometry, grid, config);
}

}  // namespace rtcl
