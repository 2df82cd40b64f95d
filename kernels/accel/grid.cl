/* Uniform grid traversal, one ray per work-item: the 3D-DDA of Amanatides &
 * Woo (1987), the lecture's t_next_x / t_next_y / t_next_z stepping
 * (均匀格点). The ray is clipped to the grid box, its first cell found from
 * the entry point, and then cells are visited in the order it crosses them.
 *
 * Stepping: integer cell coordinates (i0, i1, i2); per axis the direction's
 * sign `step` (0 for a zero component: that axis never steps and its t_next
 * is FLT_MAX, no division by zero, no inf or NaN) and t_next, the distance
 * to the cell's exit plane on that axis, recomputed from the integer index
 * and the plane's coordinate (GridHeader contract) at every step rather
 * than accumulated (no drift). The next cell is across the axis of the
 * smallest t_next, x before y before z on ties: a ray through an edge or
 * corner visits the cells around it one after another (some for an empty
 * interval), never skipping or repeating one.
 *
 * Hits: every primitive of a cell is tested (intersect_triangle_refs /
 * intersect_sphere_refs: the same arithmetic as brute force, so the same t
 * bit for bit); the closest so far stays a candidate even when it lies
 * beyond the cell (a primitive extending into later cells, met again there,
 * is then not closer). The walk ends once the candidate lies inside the
 * cell: t_best <= its exit distance, less a conservative margin (a hit
 * within rounding of the exit plane continues to the next cell). Since
 * t_best starts just above tmax, the same test ends the walk at tmax. Any
 * hit ends at the first hit in [tmin, tmax].
 *
 * Mailboxing (skipping a primitive already tested in an earlier cell) was
 * measured and not kept: see the README (Uniform grid). */
#include "shared/trace.h"

/* Coordinate of cell plane n on axis a: the host builds with the same
 * expression (src/rtcl/accel/grid.cpp). */
inline float grid_plane(const GridHeader* g, int a, int n) { return g->lower[a] + (float)n * g->cell[a]; }

/* The primitives of refs[begin .. end), up to eight at a time. Returns 1
 * when one of them was recorded in h. */
inline int grid_cell(global const int* refs, uint begin, uint end, const TraceRay* s, HitState* h,
                     global const TriangleBlock* triangles, global const SphereBlock* spheres) {
  int found = 0;
  uint k = begin;
  while (k < end) {
    int batch[8];
    int n = 0;
#ifdef RTCL_HAS_SPHERES
    while (n < 8 && k < end && refs[k] >= 0) batch[n++] = refs[k++];
#else
    while (n < 8 && k < end) batch[n++] = refs[k++];
#endif
    if (n > 0 && intersect_triangle_refs(triangles, batch, n, s, h)) {
      if (RTCL_ANY_HIT) return 1;
      found = 1;
    }
#ifdef RTCL_HAS_SPHERES
    n = 0;
    while (n < 8 && k < end && refs[k] < 0) batch[n++] = ~refs[k++];
    if (n > 0 && intersect_sphere_refs(spheres, batch, n, s, h)) {
      if (RTCL_ANY_HIT) return 1;
      found = 1;
    }
#endif
  }
  return found;
}

__attribute__((noinline)) void grid_traverse(const TraceRay* s, HitState* h, global const GridHeader* header,
                                             global const uint* cell_begin, global const int* refs,
                                             global const TriangleBlock* triangles,
                                             global const SphereBlock* spheres) {
  const GridHeader g = *header;
  const float o[3] = {s->ox, s->oy, s->oz};
  const float d[3] = {s->dx, s->dy, s->dz};
  const float inv[3] = {s->ix, s->iy, s->iz};
  /* Clip [tmin, tmax] to the box, axis by axis; an axis the ray does not
   * move along (zero component, or a reciprocal that overflows) limits
   * nothing when the origin lies within its slab and misses otherwise. */
  float t0 = s->tmin, t1 = s->tmax;
  int step[3];
  for (int a = 0; a < 3; ++a) {
    float lo = g.lower[a], hi = grid_plane(&g, a, g.res[a]);
    step[a] = (d[a] == 0.0f || !rtcl_is_finite(inv[a])) ? 0 : (d[a] > 0.0f ? 1 : -1);
    if (step[a] == 0) {
      if (o[a] < lo || o[a] > hi) return;
      continue;
    }
    float tn = ((step[a] > 0 ? lo : hi) - o[a]) * inv[a];
    float tf = ((step[a] > 0 ? hi : lo) - o[a]) * inv[a];
    /* conservative interval (Ize 2013), at every level: entering a cell
     * too early costs a test, too late a miss */
    tn -= fabs(tn) * RTCL_SLAB_WIDEN;
    tf += fabs(tf) * RTCL_SLAB_WIDEN;
    t0 = fmax(t0, tn);
    t1 = fmin(t1, tf);
  }
  if (!(t0 <= t1)) return;
  /* The first cell: the one holding the entry point (clamped into the grid). */
  int cell[3];
  float t_next[3];
  for (int a = 0; a < 3; ++a) {
    float p = step[a] == 0 ? o[a] : o[a] + t0 * d[a];
    float f = floor((p - g.lower[a]) / g.cell[a]);
    cell[a] = (int)clamp(f, 0.0f, (float)(g.res[a] - 1));
    t_next[a] = step[a] == 0 ? FLT_MAX : (grid_plane(&g, a, cell[a] + (step[a] > 0)) - o[a]) * inv[a];
  }
  for (;;) {
    uint c = (uint)cell[0] + (uint)g.res[0] * ((uint)cell[1] + (uint)g.res[1] * (uint)cell[2]);
    uint begin = cell_begin[c], end = cell_begin[c + 1];
    if (begin < end && grid_cell(refs, begin, end, s, h, triangles, spheres) && RTCL_ANY_HIT) return;
    int a = t_next[0] <= t_next[1] ? (t_next[0] <= t_next[2] ? 0 : 2) : (t_next[1] <= t_next[2] ? 1 : 2);
    float t_exit = t_next[a];
    if (h->t_best <= t_exit - fabs(t_exit) * RTCL_SLAB_WIDEN || step[a] == 0) return;
    cell[a] += step[a];
    if (cell[a] < 0 || cell[a] >= g.res[a]) return;
    t_next[a] = (grid_plane(&g, a, cell[a] + (step[a] > 0)) - o[a]) * inv[a];
  }
}

#define GRID_PARAMS                                                                                  \
  global const GridHeader *header, global const uint *cell_begin, global const int *refs,           \
      global const TriangleBlock *triangles, global const SphereBlock *spheres
#define GRID_ARGS header, cell_begin, refs, triangles, spheres
RTCL_TRACE_KERNELS(grid, GRID_PARAMS, GRID_ARGS)
