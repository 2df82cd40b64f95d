/* Uniform grid traversal, one ray per work-item: the 3D-DDA of Amanatides &
 * Woo (1987), the lecture's t_next_x / t_next_y / t_next_z stepping
 * (均匀格点). The ray is clipped to the grid box, its first cell found from
 * the entry point, and then cells are visited in the order it crosses them.
 *
 * Stepping: integer cell coordinates cell_x, cell_y, cell_z; per axis the direction's
 * sign `step` (0 for a zero component: that axis never steps and its t_next
 * is FLT_MAX, no division by zero, no inf or NaN) and t_next, the distance
 * to the cell's exit plane on that axis, recomputed from the integer index
 * and the plane's coordinate (GridHeader contract) at every step rather
 * than accumulated (no drift). The next cell is across the axis of the
 * smallest t_next, x before y before z on ties: a ray through an edge or
 * corner visits the cells around it one after another (some for an empty
 * interval), never skipping or repeating one.
 *
 * Hits: the references of the cells walked are gathered into batches of
 * eight (one per kind), and a batch is tested when full
 * (intersect_triangle_refs / intersect_sphere_refs: the same arithmetic as
 * brute force, so the same t bit for bit) or when the walk ends: on PoCL a
 * test costs the same for one lane or eight, and cells hold a few
 * primitives each. The closest hit so far stays a candidate even when it
 * lies beyond the cell it was found in (a primitive extending into later
 * cells, met again there, is then not closer). The walk ends once the
 * candidate lies inside the current cell: t_best <= its exit distance, less
 * a conservative margin (a hit within rounding of the exit plane continues
 * to the next cell); the pending batch is tested first, which can only
 * lower t_best. Every primitive of every cell up to the current one has
 * then been tested, so nothing nearer remains. Since t_best starts just
 * above tmax, the same test ends the walk at tmax. Any hit ends at the
 * first hit in [tmin, tmax].
 *
 * Measured on PoCL and not kept (README, "Uniform grid"): mailboxing
 * (skipping a reference already in the pending or the last tested batch,
 * one int8 compare each) cost more per reference than the tests it saved,
 * 0.87 against 1.14 Mrays/s on the bunny's primary rays; the step as
 * masked 4-lane vector operations instead of a branch on the axis, 0.84. */
#include "shared/trace.h"

/* Coordinate of cell plane n on axis a: the host builds with the same
 * expression (src/rtcl/accel/grid.cpp). */
inline float grid_plane(float lower, float cell, int n) { return lower + (float)n * cell; }

/* One axis of the ray against the grid: narrows [*t0, *t1] to the slab
 * (conservatively widened, Ize 2013: entering a cell too early costs a
 * test, too late a miss) and sets the axis's step, 0 when the ray does not
 * move along it (zero component, or a reciprocal that overflows); such an
 * axis limits nothing when the origin lies within its slab. Returns 0 when
 * the ray misses the slab. */
inline int grid_clip_axis(float o, float d, float inv, float lower, float cell, int res, float* t0, float* t1,
                          int* step) {
  float upper = grid_plane(lower, cell, res);
  *step = (d == 0.0f || !rtcl_is_finite(inv)) ? 0 : (d > 0.0f ? 1 : -1);
  if (*step == 0) return o >= lower && o <= upper;
  float tn = ((*step > 0 ? lower : upper) - o) * inv;
  float tf = ((*step > 0 ? upper : lower) - o) * inv;
  tn -= fabs(tn) * RTCL_SLAB_WIDEN;
  tf += fabs(tf) * RTCL_SLAB_WIDEN;
  *t0 = fmax(*t0, tn);
  *t1 = fmin(*t1, tf);
  return 1;
}

/* The first cell's coordinate on one axis (the entry point's, clamped into
 * the grid) and its exit distance along that axis (FLT_MAX when it never
 * steps). */
inline int grid_first_cell(float o, float d, float inv, float lower, float cell, int res, int step, float t0,
                           float* t_next) {
  float p = step == 0 ? o : o + t0 * d;
  int i = (int)clamp(floor((p - lower) / cell), 0.0f, (float)(res - 1));
  *t_next = step == 0 ? FLT_MAX : (grid_plane(lower, cell, i + (step > 0)) - o) * inv;
  return i;
}

#define GRID_FLUSH_TRIANGLES()                                                          \
  if (tri_count > 0) {                                                                  \
    int found = intersect_triangle_refs(triangles, tri_batch, tri_count, s, h);         \
    tri_count = 0;                                                                      \
    if (found && RTCL_ANY_HIT) return;                                                  \
  }
#ifdef RTCL_HAS_SPHERES
#define GRID_FLUSH_SPHERES()                                                            \
  if (sphere_count > 0) {                                                               \
    int found = intersect_sphere_refs(spheres, sphere_batch, sphere_count, s, h);       \
    sphere_count = 0;                                                                   \
    if (found && RTCL_ANY_HIT) return;                                                  \
  }
#else
#define GRID_FLUSH_SPHERES()
#endif
#define GRID_FINISH()     \
  {                       \
    GRID_FLUSH_TRIANGLES() \
    GRID_FLUSH_SPHERES()  \
    return;               \
  }

/* Steps the walk across axis A's exit plane: the cell coordinate, the cell
 * index (stride CELL_STRIDE) and the axis's next exit distance; finishes
 * when the ray leaves the grid or never steps on that axis. */
#define GRID_STEP(A, CELL_STRIDE)                                                              \
  {                                                                                            \
    if (step_##A == 0) GRID_FINISH()                                                           \
    cell_##A += step_##A;                                                                      \
    if (cell_##A < 0 || cell_##A >= g.res[RTCL_GRID_AXIS_##A]) GRID_FINISH()                   \
    c += step_##A * (CELL_STRIDE);                                                             \
    t_next_##A = (grid_plane(g.lower[RTCL_GRID_AXIS_##A], g.cell[RTCL_GRID_AXIS_##A],           \
                             cell_##A + (step_##A > 0)) - s->o##A) * s->i##A;                   \
  }
#define RTCL_GRID_AXIS_x 0
#define RTCL_GRID_AXIS_y 1
#define RTCL_GRID_AXIS_z 2

__attribute__((noinline)) void grid_traverse(const TraceRay* s, HitState* h, global const GridHeader* header,
                                             global const uint* cell_begin, global const int* refs,
                                             global const TriangleBlock* triangles,
                                             global const SphereBlock* spheres) {
  const GridHeader g = *header;
  float t0 = s->tmin, t1 = s->tmax;
  int step_x, step_y, step_z;
  if (!grid_clip_axis(s->ox, s->dx, s->ix, g.lower[0], g.cell[0], g.res[0], &t0, &t1, &step_x)) return;
  if (!grid_clip_axis(s->oy, s->dy, s->iy, g.lower[1], g.cell[1], g.res[1], &t0, &t1, &step_y)) return;
  if (!grid_clip_axis(s->oz, s->dz, s->iz, g.lower[2], g.cell[2], g.res[2], &t0, &t1, &step_z)) return;
  if (!(t0 <= t1)) return;
  float t_next_x, t_next_y, t_next_z;
  int cell_x = grid_first_cell(s->ox, s->dx, s->ix, g.lower[0], g.cell[0], g.res[0], step_x, t0, &t_next_x);
  int cell_y = grid_first_cell(s->oy, s->dy, s->iy, g.lower[1], g.cell[1], g.res[1], step_y, t0, &t_next_y);
  int cell_z = grid_first_cell(s->oz, s->dz, s->iz, g.lower[2], g.cell[2], g.res[2], step_z, t0, &t_next_z);
  const int stride_z = g.res[0] * g.res[1];
  int c = cell_x + g.res[0] * cell_y + stride_z * cell_z;
  int tri_batch[8];
  int tri_count = 0;
#ifdef RTCL_HAS_SPHERES
  int sphere_batch[8];
  int sphere_count = 0;
#endif
  for (;;) {
    uint end = cell_begin[c + 1];
    for (uint k = cell_begin[c]; k < end; ++k) {
      int r = refs[k];
#ifdef RTCL_HAS_SPHERES
      if (r < 0) {
        sphere_batch[sphere_count++] = ~r;
        if (sphere_count == 8) GRID_FLUSH_SPHERES()
        continue;
      }
#endif
      tri_batch[tri_count++] = r;
      if (tri_count == 8) GRID_FLUSH_TRIANGLES()
    }
    if (t_next_x <= t_next_y && t_next_x <= t_next_z) {
      if (h->t_best <= t_next_x - fabs(t_next_x) * RTCL_SLAB_WIDEN) GRID_FINISH()
      GRID_STEP(x, 1)
    } else if (t_next_y <= t_next_z) {
      if (h->t_best <= t_next_y - fabs(t_next_y) * RTCL_SLAB_WIDEN) GRID_FINISH()
      GRID_STEP(y, g.res[0])
    } else {
      if (h->t_best <= t_next_z - fabs(t_next_z) * RTCL_SLAB_WIDEN) GRID_FINISH()
      GRID_STEP(z, stride_z)
    }
  }
}

#define GRID_PARAMS                                                                                  \
  global const GridHeader *header, global const uint *cell_begin, global const int *refs,           \
      global const TriangleBlock *triangles, global const SphereBlock *spheres
#define GRID_ARGS header, cell_begin, refs, triangles, spheres
RTCL_TRACE_KERNELS(grid, GRID_PARAMS, GRID_ARGS)
