/* Uniform grid traversal, one ray per work-item: the 3D-DDA of Amanatides &
 * Woo (1987), the lecture's t_next_x / t_next_y / t_next_z stepping
 * (均匀格点), with empty-space skipping. GridHeader (shared/layouts.h)
 * defines the cells, macrocells, occupied-space boxes and reference lanes.
 *
 * Entry: the ray against the occupied-space boxes (eight octant boxes in one
 * float8 slab test, then the eight sub-octant boxes of each octant it meets)
 * gives [t0, t1], outside which no primitive lies; a ray that meets none
 * misses without a walk. The walk starts in the cell of the point at t0
 * (clamped into the grid) and ends once the next exit distance passes t1.
 *
 * Stepping: integer cell coordinates cell_x, cell_y, cell_z; per axis the
 * direction's sign `step` (0 for a zero component: that axis never steps
 * and its t_next is FLT_MAX, no division by zero, no inf or NaN) and
 * t_next, the distance to the cell's exit plane on that axis, recomputed
 * from the integer index and the plane's coordinate at every step rather
 * than accumulated (no drift). The next cell is across the axis of the
 * smallest t_next, x before y before z on ties: a ray through an edge or
 * corner visits the cells around it one after another (some for an empty
 * interval), never skipping or repeating one. In an empty macrocell the
 * same stepping runs on macrocell planes, which are cell planes computed by
 * the same expression; entering an occupied macrocell the walk resumes in
 * the cell holding the entry point (grid_entry_cell).
 *
 * Hits: each cell's triangles are tested as it is visited, in runs of up to
 * eight contiguous reference lanes (intersect_triangle_run: float8 loads,
 * no gather; the same arithmetic as brute force, so the same t bit for
 * bit); spheres, rare in grids, are gathered by reference into batches of
 * eight (intersect_sphere_refs) tested when full or when the walk ends.
 * The closest hit so far stays a candidate even when it lies beyond the
 * cell it was found in (a primitive extending into later cells, met again
 * there, is then not closer). The walk ends once the candidate lies inside
 * the current cell: t_best <= its exit distance, less a conservative margin
 * (a hit within rounding of the exit plane continues to the next cell).
 * Every primitive of every cell up to the current one has then been
 * tested, so nothing nearer remains. Since t_best starts just above tmax,
 * the same test ends the walk at tmax. Any hit ends at the first hit in
 * [tmin, tmax]. */
#include "shared/trace.h"

/* Coordinate of cell plane n on axis a: the host builds with the same
 * expression (src/rtcl/accel/grid.cpp). */
inline float grid_plane(float lower, float cell, int n) { return lower + (float)n * cell; }

/* The direction's sign on one axis, 0 when the ray does not move along it
 * (zero component, or a reciprocal that overflows): that axis never
 * steps. */
inline int grid_step(float d, float inv) { return (d == 0.0f || !rtcl_is_finite(inv)) ? 0 : (d > 0.0f ? 1 : -1); }

#ifdef RTCL_HAS_SPHERES
#define GRID_FLUSH_SPHERES()                                                            \
  if (sphere_count > 0) {                                                               \
    int found = intersect_sphere_refs(spheres, sphere_batch, sphere_count, s, h);       \
    sphere_count = 0;                                                                   \
    if (found && RTCL_ANY_HIT) return -1;                                               \
  }
#else
#define GRID_FLUSH_SPHERES()
#endif
#define GRID_FINISH()     \
  {                       \
    GRID_FLUSH_SPHERES()  \
    return -1;            \
  }

/* Steps the walk across axis A's exit plane: the cell coordinate, the cell
 * index (stride CELL_STRIDE) and the axis's next exit distance; finishes
 * when the ray leaves the grid or never steps on that axis. A step into
 * another macrocell moves the macrocell coordinate with it, and the walk
 * goes on cell by cell there if it is occupied, else macrocell by
 * macrocell. */
#define GRID_STEP(A, CELL_STRIDE, MACRO_STRIDE)                                                 \
  {                                                                                            \
    if (step_##A == 0) GRID_FINISH()                                                           \
    cell_##A += step_##A;                                                                      \
    if (cell_##A < 0 || cell_##A >= g.res[RTCL_GRID_AXIS_##A]) GRID_FINISH()                   \
    c += step_##A * (CELL_STRIDE);                                                             \
    t_next_##A = (grid_plane(g.lower[RTCL_GRID_AXIS_##A], g.cell[RTCL_GRID_AXIS_##A],           \
                             cell_##A + (step_##A > 0)) - s->o##A) * s->i##A;                   \
    if ((cell_##A >> shift) != macro_##A) {                                                    \
      macro_##A += step_##A;                                                                   \
      m += step_##A * (MACRO_STRIDE);                                                          \
      m_next_##A = grid_macro_exit(s->o##A, s->i##A, g.lower[RTCL_GRID_AXIS_##A],             \
                                   g.cell[RTCL_GRID_AXIS_##A], g.res[RTCL_GRID_AXIS_##A], shift, \
                                   macro_##A, step_##A);                                       \
      occupied = macro_occupied[m];                                                            \
    }                                                                                          \
  }

/* Crosses empty macrocell space on axis A: the macrocell coordinate, index
 * and next exit distance; finishes when the ray leaves the grid. Entering
 * an occupied macrocell at distance t_cross, the walk resumes cell by cell
 * from the cell the ray enters: on axis A the first one of the macrocell
 * in the step direction, on the others the one holding the entry point. */
#define GRID_MACRO_STEP(A)                                                                     \
  {                                                                                            \
    if (step_##A == 0) GRID_FINISH()                                                           \
    float t_cross = m_next_##A;                                                                \
    macro_##A += step_##A;                                                                     \
    if (macro_##A < 0 || macro_##A >= g.macro[RTCL_GRID_AXIS_##A]) GRID_FINISH()               \
    m += step_##A * macro_stride_##A;                                                          \
    m_next_##A = grid_macro_exit(s->o##A, s->i##A, g.lower[RTCL_GRID_AXIS_##A],               \
                                 g.cell[RTCL_GRID_AXIS_##A], g.res[RTCL_GRID_AXIS_##A], shift,   \
                                 macro_##A, step_##A);                                         \
    occupied = macro_occupied[m];                                                              \
    if (occupied) {                                                                            \
      cell_x = grid_entry_cell(s->ox, s->dx, s->ix, g.lower[0], g.cell[0], g.res[0], shift, macro_x, step_x, \
                               t_cross, &t_next_x);                                            \
      cell_y = grid_entry_cell(s->oy, s->dy, s->iy, g.lower[1], g.cell[1], g.res[1], shift, macro_y, step_y, \
                               t_cross, &t_next_y);                                            \
      cell_z = grid_entry_cell(s->oz, s->dz, s->iz, g.lower[2], g.cell[2], g.res[2], shift, macro_z, step_z, \
                               t_cross, &t_next_z);                                            \
      c = cell_x + g.res[0] * cell_y + stride_z * cell_z;                                      \
    }                                                                                          \
  }
#define RTCL_GRID_AXIS_x 0
#define RTCL_GRID_AXIS_y 1
#define RTCL_GRID_AXIS_z 2

/* Exit distance of macrocell `macro` on one axis: its last cell plane in
 * the step direction (the grid's last plane for a partial macrocell);
 * FLT_MAX when the axis never steps. */
inline float grid_macro_exit(float o, float inv, float lower, float cell, int res, int shift, int macro, int step) {
  if (step == 0) return FLT_MAX;
  int n = step > 0 ? min((macro + 1) << shift, res) : macro << shift;
  return (grid_plane(lower, cell, n) - o) * inv;
}

/* The cell on one axis where a walk entering cells [first, last] at
 * distance t starts, and that cell's exit distance (FLT_MAX for an axis that
 * never steps). The entry point's cell, clamped into the range; if rounding
 * put it one cell ahead (the ray crosses into it only after t), the one
 * before: a cell visited early costs a test, one skipped could miss a hit.
 * On an axis whose plane the ray crosses at t the entry point lies on the
 * range's face, and the clamp gives the first cell in the step direction. */
inline int grid_cell_at(float o, float d, float inv, float lower, float cell, int first, int last, int step,
                        float t, float* t_next) {
  float p = step == 0 ? o : o + t * d;
  int i = (int)clamp(floor((p - lower) / cell), (float)first, (float)last);
  if (step == 0) {
    *t_next = FLT_MAX;
    return i;
  }
  float t_enter = (grid_plane(lower, cell, i + (step < 0)) - o) * inv;
  if (t_enter > t && i != (step > 0 ? first : last)) i -= step;
  *t_next = (grid_plane(lower, cell, i + (step > 0)) - o) * inv;
  return i;
}

/* The same within macrocell `macro` (its cells, on one axis). */
inline int grid_entry_cell(float o, float d, float inv, float lower, float cell, int res, int shift, int macro,
                           int step, float t, float* t_next) {
  return grid_cell_at(o, d, inv, lower, cell, macro << shift, min((macro + 1) << shift, res) - 1, step, t, t_next);
}

/* The reference lanes [begin, end) of one cell, eight triangles a run,
 * against the ray; whether one hit (at any hit the first run that hits
 * ends the test). */
inline int grid_cell_triangles(global const float* lanes, int lane_stride, global const int* lane_prims, uint begin,
                               uint end, const TraceRay* s, HitState* h) {
  int found = 0;
  for (uint k = begin; k < end; k += 8) {
    found |= intersect_triangle_run(lanes, lane_stride, lane_prims, k, (int)min(end - k, 8u), s, h);
    if (found && RTCL_ANY_HIT) break;
  }
  return found;
}

/* Returns the cell (its index) whose triangles ended an any-hit traversal,
 * else -1 (also when a batch of spheres, gathered over several cells, ended
 * it). */
__attribute__((noinline)) int grid_traverse(const TraceRay* s, HitState* h, global const GridHeader* header,
                                            global const uint* cell_begin, global const int* refs,
                                            global const uchar* macro_occupied,
                                            global const float8* occupied_boxes, global const float* lanes,
                                            global const int* lane_prims, global const SphereBlock* spheres) {
  const GridHeader g = *header;
  /* The occupied space: the ray's interval over the octant boxes it meets,
   * narrowed to the sub-octant boxes it meets in them (widened slabs,
   * shared/box.h); nothing to find outside [t0, t1]. */
  float8 t_in, t_out;
  int8 hit = intersect_box_rows8((global const float8*)header->occupied_bounds, s, s->tmax, &t_in, &t_out);
  if (!any(hit)) return -1;
  int octants[8];
  vstore8(hit, 0, octants);
  float8 t_first = (float8)(INFINITY), t_last = (float8)(-INFINITY);
  for (int o = 0; o < 8; ++o) {
    if (!octants[o]) continue;
    hit = intersect_box_rows8(occupied_boxes + 6 * o, s, s->tmax, &t_in, &t_out);
    t_first = fmin(t_first, select((float8)(INFINITY), t_in, hit));
    t_last = fmax(t_last, select((float8)(-INFINITY), t_out, hit));
  }
  const float4 in4 = fmin(t_first.lo, t_first.hi), out4 = fmax(t_last.lo, t_last.hi);
  const float t0 = fmin(fmin(in4.x, in4.y), fmin(in4.z, in4.w));
  const float t1 = fmax(fmax(out4.x, out4.y), fmax(out4.z, out4.w));
  if (!(t0 <= t1)) return -1;
  const int step_x = grid_step(s->dx, s->ix), step_y = grid_step(s->dy, s->iy), step_z = grid_step(s->dz, s->iz);
  float t_next_x, t_next_y, t_next_z;
  int cell_x = grid_cell_at(s->ox, s->dx, s->ix, g.lower[0], g.cell[0], 0, g.res[0] - 1, step_x, t0, &t_next_x);
  int cell_y = grid_cell_at(s->oy, s->dy, s->iy, g.lower[1], g.cell[1], 0, g.res[1] - 1, step_y, t0, &t_next_y);
  int cell_z = grid_cell_at(s->oz, s->dz, s->iz, g.lower[2], g.cell[2], 0, g.res[2] - 1, step_z, t0, &t_next_z);
  const int stride_z = g.res[0] * g.res[1];
  int c = cell_x + g.res[0] * cell_y + stride_z * cell_z;
  const int shift = g.macro[3];
  const int macro_stride_x = 1, macro_stride_y = g.macro[0], macro_stride_z = g.macro[0] * g.macro[1];
  int macro_x = cell_x >> shift, macro_y = cell_y >> shift, macro_z = cell_z >> shift;
  int m = macro_x + macro_stride_y * macro_y + macro_stride_z * macro_z;
  float m_next_x = grid_macro_exit(s->ox, s->ix, g.lower[0], g.cell[0], g.res[0], shift, macro_x, step_x);
  float m_next_y = grid_macro_exit(s->oy, s->iy, g.lower[1], g.cell[1], g.res[1], shift, macro_y, step_y);
  float m_next_z = grid_macro_exit(s->oz, s->iz, g.lower[2], g.cell[2], g.res[2], shift, macro_z, step_z);
  int occupied = macro_occupied[m];
#ifdef RTCL_HAS_SPHERES
  int sphere_batch[8];
  int sphere_count = 0;
#endif
  for (;;) {
    if (!occupied) {
      if (m_next_x <= m_next_y && m_next_x <= m_next_z) {
        if (h->t_best <= m_next_x - fabs(m_next_x) * RTCL_SLAB_WIDEN || m_next_x > t1) GRID_FINISH()
        GRID_MACRO_STEP(x)
      } else if (m_next_y <= m_next_z) {
        if (h->t_best <= m_next_y - fabs(m_next_y) * RTCL_SLAB_WIDEN || m_next_y > t1) GRID_FINISH()
        GRID_MACRO_STEP(y)
      } else {
        if (h->t_best <= m_next_z - fabs(m_next_z) * RTCL_SLAB_WIDEN || m_next_z > t1) GRID_FINISH()
        GRID_MACRO_STEP(z)
      }
      continue;
    }
    const uint begin = cell_begin[c], end = cell_begin[c + 1];
    if (grid_cell_triangles(lanes, g.lane_stride, lane_prims, begin, end, s, h) && RTCL_ANY_HIT) return c;
#ifdef RTCL_HAS_SPHERES
    for (uint k = begin; k < end; ++k) {
      int r = refs[k];
      if (r >= 0) continue;
      sphere_batch[sphere_count++] = ~r;
      if (sphere_count == 8) GRID_FLUSH_SPHERES()
    }
#endif
    if (t_next_x <= t_next_y && t_next_x <= t_next_z) {
      if (h->t_best <= t_next_x - fabs(t_next_x) * RTCL_SLAB_WIDEN || t_next_x > t1) GRID_FINISH()
      GRID_STEP(x, 1, macro_stride_x)
    } else if (t_next_y <= t_next_z) {
      if (h->t_best <= t_next_y - fabs(t_next_y) * RTCL_SLAB_WIDEN || t_next_y > t1) GRID_FINISH()
      GRID_STEP(y, g.res[0], macro_stride_y)
    } else {
      if (h->t_best <= t_next_z - fabs(t_next_z) * RTCL_SLAB_WIDEN || t_next_z > t1) GRID_FINISH()
      GRID_STEP(z, stride_z, macro_stride_z)
    }
  }
}

#define GRID_PARAMS                                                                                  \
  global const GridHeader *header, global const uint *cell_begin, global const int *refs,           \
      global const uchar *macro_occupied, global const float8 *occupied_boxes, global const float *lanes, \
      global const int *lane_prims, global const SphereBlock *spheres
#define GRID_ARGS header, cell_begin, refs, macro_occupied, occupied_boxes, lanes, lane_prims, spheres
/* Cell `cell`'s primitives against the ray; whether one hit (any hit). */
inline int grid_leaf(int cell, const TraceRay* s, HitState* h, GRID_PARAMS) {
  const uint begin = cell_begin[cell], end = cell_begin[cell + 1];
  if (grid_cell_triangles(lanes, header->lane_stride, lane_prims, begin, end, s, h)) return 1;
#ifdef RTCL_HAS_SPHERES
  int batch[8];
  int count = 0;
  for (uint k = begin; k < end; ++k) {
    if (refs[k] >= 0) continue;
    batch[count++] = ~refs[k];
    if (count == 8) {
      if (intersect_sphere_refs(spheres, batch, count, s, h)) return 1;
      count = 0;
    }
  }
  if (count > 0 && intersect_sphere_refs(spheres, batch, count, s, h)) return 1;
#endif
  return 0;
}
RTCL_TRACE_KERNELS_OCCLUDER_CACHE(grid, GRID_PARAMS, GRID_ARGS)
