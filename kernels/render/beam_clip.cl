/* Beam clipping (Heckbert and Hanrahan 1984; lecture, 反射光束跟踪过程（2）),
 * one work-item per beam (a tile of the viewing beam, or a reflected beam): walk the beam's candidate polygons front to
 * back; fragment = beam ∩ polygon (Sutherland–Hodgman); record it; beam −=
 * fragment (the beam's remainder split along the polygon's edges into
 * disjoint convex pieces); stop when the beam is empty or the list is
 * exhausted. With exact != 0 a fragment first gives up the part where a
 * later candidate's plane is nearer (a half-plane in screen space: 1/s is
 * affine there for a plane), which makes the walk exact for any arrangement
 * of planar polygons. The same walk in double on the host:
 * src/rtcl/beam/beam_clip_host.cpp.
 *
 * Coordinates are beam-local pixels in float (|x|, |y| <= the polygon's
 * extent clipped to the screen; polygons arrive clipped to it). Pieces below
 * min_area_fraction * the beam's area are dropped. Limits (beam_layouts.h): a
 * region of more than RTCL_BEAM_MAX_PIECES pieces or a piece of more than
 * RTCL_BEAM_PIECE_VERTS vertices stops the beam, is counted in status and
 * marks over_limit[beam] (the host splits such a beam and clips again);
 * fragments beyond `capacity` are counted, not written: the host reports or
 * retries, nothing is cut silently. */
#include "shared/layouts.h"
#include "shared/beam_layouts.h"

typedef struct Piece {
  uint n;
  float2 v[RTCL_BEAM_PIECE_VERTS];
} Piece;

#define CLIP_OK 0
#define CLIP_VERTS 1
#define CLIP_PIECES 2

inline float piece_area(const Piece* p) {
  float s = 0.0f;
  for (uint i = 0; i < p->n; ++i) {
    float2 a = p->v[i], b = p->v[(i + 1) % p->n];
    s += a.x * b.y - b.x * a.y;
  }
  return 0.5f * s;
}

/* The inside (left) half-plane a x + b y + c >= 0 of edge i of a
 * counter-clockwise piece. */
inline float3 edge_plane(const Piece* p, uint i) {
  float2 a = p->v[i], b = p->v[(i + 1) % p->n];
  float3 h;
  h.x = -(b.y - a.y);
  h.y = b.x - a.x;
  h.z = -(h.x * a.x + h.y * a.y);
  return h;
}

/* Sutherland–Hodgman against one half-plane (points on the line kept).
 * A vertex within `merge` (max norm) of the previous one is dropped: float
 * rounding leaves near-copies of a vertex where several edges meet, and the
 * edge between them would bound nothing reliably. */
inline int near_vertex(float2 a, float2 b, float merge) {
  float2 d = fabs(a - b);
  return fmax(d.x, d.y) <= merge;
}

inline int clip_piece(const Piece* in, float3 h, Piece* out, float merge) {
  out->n = 0;
  if (in->n < 3) return CLIP_OK;
  for (uint i = 0; i < in->n; ++i) {
    float2 p = in->v[i], q = in->v[(i + 1) % in->n];
    float dp = h.x * p.x + h.y * p.y + h.z, dq = h.x * q.x + h.y * q.y + h.z;
    if (dp >= 0.0f) {
      if (out->n == RTCL_BEAM_PIECE_VERTS) return CLIP_VERTS;
      if (out->n == 0 || !near_vertex(out->v[out->n - 1], p, merge)) out->v[out->n++] = p;
    }
    if ((dp > 0.0f && dq < 0.0f) || (dp < 0.0f && dq > 0.0f)) {
      float2 x = p + (dp / (dp - dq)) * (q - p);
      if (out->n == RTCL_BEAM_PIECE_VERTS) return CLIP_VERTS;
      if (out->n == 0 || !near_vertex(out->v[out->n - 1], x, merge)) out->v[out->n++] = x;
    }
  }
  while (out->n > 1 && near_vertex(out->v[0], out->v[out->n - 1], merge)) out->n--;
  if (out->n < 3) out->n = 0;
  return CLIP_OK;
}

inline int disjoint_boxes(const Piece* a, const Piece* b) {
  float2 alo = a->v[0], ahi = a->v[0], blo = b->v[0], bhi = b->v[0];
  for (uint i = 1; i < a->n; ++i) {
    alo = fmin(alo, a->v[i]);
    ahi = fmax(ahi, a->v[i]);
  }
  for (uint i = 1; i < b->n; ++i) {
    blo = fmin(blo, b->v[i]);
    bhi = fmax(bhi, b->v[i]);
  }
  return ahi.x < blo.x || bhi.x < alo.x || ahi.y < blo.y || bhi.y < alo.y;
}

/* *a = *a ∩ convex. */
inline int intersect_piece(Piece* a, const Piece* convex, Piece* tmp, float merge) {
  if (a->n < 3 || convex->n < 3 || disjoint_boxes(a, convex)) {
    a->n = 0;
    return CLIP_OK;
  }
  for (uint e = 0; e < convex->n && a->n >= 3; ++e) {
    int r = clip_piece(a, edge_plane(convex, e), tmp, merge);
    if (r != CLIP_OK) return r;
    *a = *tmp;
  }
  return CLIP_OK;
}

inline int push_piece(Piece* region, uint* count, const Piece* p) {
  if (*count == RTCL_BEAM_MAX_PIECES) return CLIP_PIECES;
  region[(*count)++] = *p;
  return CLIP_OK;
}

/* Appends the pieces of b − convex of area >= min_area to region. */
inline int subtract_piece(const Piece* b, const Piece* convex, float min_area, Piece* region, uint* count,
                          Piece* rest, Piece* tmp, float merge) {
  if (b->n < 3 || piece_area(b) < min_area) return CLIP_OK;
  if (convex->n < 3 || disjoint_boxes(b, convex)) return push_piece(region, count, b);
  *rest = *b;
  for (uint e = 0; e < convex->n; ++e) {
    float3 h = edge_plane(convex, e);
    /* A zero-length edge (vertices equal after rounding to float) bounds
     * nothing; its zero half-plane would hold the whole piece on both sides. */
    if (near_vertex(convex->v[e], convex->v[(e + 1) % convex->n], merge)) continue;
    int r = clip_piece(rest, -h, tmp, merge); /* outside edge e, inside edges 0 .. e-1 */
    if (r != CLIP_OK) return r;
    if (tmp->n >= 3 && piece_area(tmp) >= min_area) {
      r = push_piece(region, count, tmp);
      if (r != CLIP_OK) return r;
    }
    r = clip_piece(rest, h, tmp, merge);
    if (r != CLIP_OK) return r;
    *rest = *tmp;
    if (rest->n < 3) break;
  }
  return CLIP_OK;
}

/* region[start .. *end) −= convex, through scratch. */
inline int subtract_range(Piece* region, uint start, uint* end, const Piece* convex, float min_area, Piece* scratch,
                          Piece* rest, Piece* tmp, float merge) {
  uint m = 0;
  for (uint i = start; i < *end; ++i) {
    int r = subtract_piece(region + i, convex, min_area, scratch, &m, rest, tmp, merge);
    if (r != CLIP_OK) return r;
  }
  if (start + m > RTCL_BEAM_MAX_PIECES) return CLIP_PIECES;
  for (uint i = 0; i < m; ++i) region[start + i] = scratch[i];
  *end = start + m;
  return CLIP_OK;
}

/* Consecutive vertices within `merge` (a sliver's) are dropped. */
inline void load_polygon(global const BeamPolygon* p, float2 origin, Piece* out, float merge) {
  out->n = 0;
  for (uint i = 0; i < p->count && i < RTCL_BEAM_POLYGON_VERTS; ++i) {
    float2 v = (float2)(p->x[i], p->y[i]) - origin;
    if (out->n == 0 || !near_vertex(out->v[out->n - 1], v, merge)) out->v[out->n++] = v;
  }
  while (out->n > 1 && near_vertex(out->v[0], out->v[out->n - 1], merge)) out->n--;
  if (out->n < 3) out->n = 0;
}

/* 1/s of a polygon's plane in beam-local coordinates. */
inline float3 local_inv_depth(global const BeamPolygon* p, float2 origin) {
  float a = p->inv_depth[0], b = p->inv_depth[1];
  return (float3)(a, b, p->inv_depth[2] + a * origin.x + b * origin.y);
}

inline void report(global volatile uint* status, global uint* over_limit, int code, uint tile) {
  atomic_inc(status + (code == CLIP_PIECES ? RTCL_BEAM_STATUS_PIECE_OVERFLOW : RTCL_BEAM_STATUS_VERT_OVERFLOW));
  atomic_min(status + RTCL_BEAM_STATUS_FIRST_TILE, tile);
  over_limit[tile] = 1;
}

kernel void clip_beams(global const BeamPolygon* polygons, global const Beam* beams, global const uint* candidates,
                       uint beam_count, uint exact, float min_area_fraction, global BeamFragment* fragments,
                       uint capacity, global volatile uint* status, global uint* over_limit) {
  uint ti = get_global_id(0);
  if (ti >= beam_count) return;
  global const Beam* t = beams + ti;
  const float2 origin = (float2)(t->x0, t->y0);
  Piece beam[RTCL_BEAM_MAX_PIECES], next[RTCL_BEAM_MAX_PIECES], kept[RTCL_BEAM_MAX_PIECES],
      scratch[RTCL_BEAM_MAX_PIECES];
  Piece poly, f, q, front, rest, tmp;
  uint nb = 1, seq = 0;
  beam[0].n = min(t->vertex_count, (uint)RTCL_BEAM_PIECE_VERTS);
  for (uint i = 0; i < beam[0].n; ++i) beam[0].v[i] = (float2)(t->x[i], t->y[i]) - origin;
  const float min_area = min_area_fraction * piece_area(beam);
  /* Vertex merge distance: 8 float ulps of the beam's extent (its local
   * coordinates' rounding is about one). */
  float extent = 0.0f;
  for (uint i = 0; i < beam[0].n; ++i) extent = fmax(extent, fmax(fabs(beam[0].v[i].x), fabs(beam[0].v[i].y)));
  const float merge = 8.0f * FLT_EPSILON * extent;
  const uint first = t->first, count = t->count;
  int r = CLIP_OK;
  for (uint c = 0; c < count && nb > 0 && r == CLIP_OK; ++c) {
    uint pi = candidates[first + c];
    load_polygon(polygons + pi, origin, &poly, merge);
    float3 pd = local_inv_depth(polygons + pi, origin);
    uint nn = 0;
    for (uint i = 0; i < nb && r == CLIP_OK; ++i) {
      f = beam[i];
      r = intersect_piece(&f, &poly, &tmp, merge);
      if (r != CLIP_OK) break;
      if (f.n < 3 || piece_area(&f) < min_area) {
        r = push_piece(next, &nn, beam + i);
        continue;
      }
      uint nk = 1, gave_up = 0;
      kept[0] = f;
      for (uint l = c + 1; exact && l < count && nk > 0 && r == CLIP_OK; ++l) {
        uint qi = candidates[first + l];
        load_polygon(polygons + qi, origin, &q, merge);
        r = clip_piece(&q, local_inv_depth(polygons + qi, origin) - pd, &front, merge); /* where qi is nearer */
        if (r != CLIP_OK || front.n < 3) continue;
        uint before = nk;
        float area_before = 0.0f, area_after = 0.0f;
        for (uint k = 0; k < nk; ++k) area_before += piece_area(kept + k);
        r = subtract_range(kept, 0, &nk, &front, min_area, scratch, &rest, &tmp, merge);
        for (uint k = 0; k < nk; ++k) area_after += piece_area(kept + k);
        if (nk != before || area_after != area_before) gave_up = 1;
      }
      if (r != CLIP_OK) break;
      for (uint k = 0; k < nk; ++k) {
        uint slot = atomic_inc(status + RTCL_BEAM_STATUS_FRAGMENTS);
        if (slot >= capacity) continue;
        global BeamFragment* out = fragments + slot;
        out->beam = ti;
        out->polygon = pi;
        out->seq = seq++;
        out->count = kept[k].n;
        for (uint j = 0; j < kept[k].n; ++j) {
          out->x[j] = kept[k].v[j].x + origin.x;
          out->y[j] = kept[k].v[j].y + origin.y;
        }
      }
      r = subtract_piece(beam + i, &poly, min_area, next, &nn, &rest, &tmp, merge);
      if (r != CLIP_OK || !gave_up) continue;
      /* f's part where later candidates are nearer goes back to the beam. */
      uint start = nn;
      r = push_piece(next, &nn, &f);
      for (uint k = 0; k < nk && r == CLIP_OK; ++k)
        r = subtract_range(next, start, &nn, kept + k, min_area, scratch, &rest, &tmp, merge);
    }
    if (r != CLIP_OK) break;
    for (uint i = 0; i < nn; ++i) beam[i] = next[i];
    nb = nn;
  }
  if (r != CLIP_OK) report(status, over_limit, r, ti);
}
