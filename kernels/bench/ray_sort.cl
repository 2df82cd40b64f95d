/* Rays sorted on the device before tracing (bench/ray_sort/ray_sort_ab.cpp,
 * README "Kernel levers on the single-ray BVH"): a stable counting sort of
 * the ray records by a short key, so that rays traced next to each other
 * start near each other (and go the same way), and the traversal's nodes
 * stay in cache; the hits traced in sorted order are put back afterwards.
 *
 * Key (RTCL_SORT_BUCKETS = 2^(3 * (ORIGIN_BITS + DIRECTION_BITS)) values):
 * the Morton code of the origin quantised to 2^RTCL_SORT_ORIGIN_BITS cells
 * per axis within [lo, lo + extent] (origins outside clamp to its faces,
 * NaN to cell 0), and the Morton code of the unit direction quantised to
 * 2^RTCL_SORT_DIRECTION_BITS cells per axis on [-1, 1] (1 bit: its
 * octant); the direction's bits are the low ones unless
 * RTCL_SORT_DIRECTION_HIGH. Any ray, valid or not, gets a key in range.
 *
 * Three passes over C chunks of `chunk` consecutive rays (one work-item a
 * chunk, C = the global size of ray_sort_count and ray_sort_scatter):
 *   ray_sort_count   counts[c * BUCKETS + b] = rays of chunk c with key b
 *   ray_sort_offsets the exclusive prefix sum in (bucket, chunk) order
 *   ray_sort_scatter each chunk writes its rays, in their order, at its
 *                    offsets: sorted[k] = rays[order[k]]
 * Equal keys keep their input order (stable), so the order is a function of
 * the rays alone. ray_sort_unsort_hits puts hits traced in sorted order back:
 * hits[order[k]] = sorted_hits[k]. */
#include "shared/layouts.h"

#ifndef RTCL_SORT_ORIGIN_BITS
#define RTCL_SORT_ORIGIN_BITS 3
#endif
#ifndef RTCL_SORT_DIRECTION_BITS
#define RTCL_SORT_DIRECTION_BITS 1
#endif
#define RTCL_SORT_KEY_BITS (3 * (RTCL_SORT_ORIGIN_BITS + RTCL_SORT_DIRECTION_BITS))
#define RTCL_SORT_BUCKETS (1u << RTCL_SORT_KEY_BITS)

/* x scaled to cells (0 .. cells - 1), clamped; NaN -> 0. */
inline uint ray_sort_cell(float f, uint cells) {
  if (!(f > 0.0f)) return 0;
  if (f >= (float)cells) return cells - 1;
  return min(cells - 1, (uint)f);
}

/* The bits of three cell coordinates of `bits` bits each, interleaved (x
 * highest). */
inline uint ray_sort_morton3(uint x, uint y, uint z, int bits) {
  uint code = 0;
  for (int b = bits - 1; b >= 0; --b) code = code << 3 | ((x >> b) & 1u) << 2 | ((y >> b) & 1u) << 1 | ((z >> b) & 1u);
  return code;
}

/* lo: the lower corner of the box the origins are binned in; scale: cells per
 * scene unit on each axis (2^ORIGIN_BITS / extent; 0 on a flat axis). */
inline uint ray_sort_key(Ray r, float4 lo, float4 scale) {
  const uint oc = 1u << RTCL_SORT_ORIGIN_BITS;
  uint origin = ray_sort_morton3(ray_sort_cell((r.ox - lo.x) * scale.x, oc), ray_sort_cell((r.oy - lo.y) * scale.y, oc),
                                 ray_sort_cell((r.oz - lo.z) * scale.z, oc), RTCL_SORT_ORIGIN_BITS);
#if RTCL_SORT_DIRECTION_BITS == 0
  return origin;
#else
  const uint dc = 1u << RTCL_SORT_DIRECTION_BITS;
#if RTCL_SORT_DIRECTION_BITS == 1
  float inv = 1.0f; /* the octant: the sign decides, no length needed */
#else
  float inv = rsqrt(r.dx * r.dx + r.dy * r.dy + r.dz * r.dz);
#endif
  float half_cells = 0.5f * (float)dc;
  uint direction = ray_sort_morton3(ray_sort_cell((r.dx * inv + 1.0f) * half_cells, dc),
                                    ray_sort_cell((r.dy * inv + 1.0f) * half_cells, dc),
                                    ray_sort_cell((r.dz * inv + 1.0f) * half_cells, dc), RTCL_SORT_DIRECTION_BITS);
#ifdef RTCL_SORT_DIRECTION_HIGH
  return direction << (3 * RTCL_SORT_ORIGIN_BITS) | origin;
#else
  return origin << (3 * RTCL_SORT_DIRECTION_BITS) | direction;
#endif
#endif
}

kernel void ray_sort_count(global const Ray* rays, uint ray_count, uint chunk, float4 lo, float4 scale,
                           global uint* counts) {
  size_t c = get_global_id(0);
  global uint* row = counts + c * RTCL_SORT_BUCKETS;
  for (uint b = 0; b < RTCL_SORT_BUCKETS; ++b) row[b] = 0;
  ulong begin = (ulong)c * chunk, end = min(begin + chunk, (ulong)ray_count);
  for (ulong i = begin; i < end; ++i) ++row[ray_sort_key(rays[i], lo, scale)];
}

/* One work-item. */
kernel void ray_sort_offsets(global uint* counts, uint chunks) {
  uint running = 0;
  for (uint b = 0; b < RTCL_SORT_BUCKETS; ++b)
    for (uint c = 0; c < chunks; ++c) {
      size_t at = (size_t)c * RTCL_SORT_BUCKETS + b;
      uint n = counts[at];
      counts[at] = running;
      running += n;
    }
}

kernel void ray_sort_scatter(global const Ray* rays, uint ray_count, uint chunk, float4 lo, float4 scale,
                             global uint* offsets, global Ray* sorted, global uint* order) {
  size_t c = get_global_id(0);
  global uint* row = offsets + c * RTCL_SORT_BUCKETS;
  ulong begin = (ulong)c * chunk, end = min(begin + chunk, (ulong)ray_count);
  for (ulong i = begin; i < end; ++i) {
    Ray r = rays[i];
    uint k = row[ray_sort_key(r, lo, scale)]++;
    sorted[k] = r;
    order[k] = (uint)i;
  }
}

kernel void ray_sort_unsort_hits(global const Hit* sorted_hits, global const uint* order, uint ray_count,
                                 global Hit* hits) {
  uint k = get_global_id(0);
  if (k < ray_count) hits[order[k]] = sorted_hits[k];
}
