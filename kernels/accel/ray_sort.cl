/* Rays sorted on the device before a Coherence::scattered trace
 * (src/rtcl/accel/ray_sort.hpp): a stable counting sort of the ray indices
 * by a short key, so that rays traced one after another start near each
 * other and go the same way, and the nodes they visit stay in cache. The
 * trace then reads rays[order[k]] and writes its hit at hits[order[k]]
 * (RTCL_TRACE_ORDER, kernels/shared/trace.h); the ray records stay where
 * they are.
 *
 * Key (RTCL_SORT_BUCKETS = 2^(3 * RTCL_SORT_ORIGIN_BITS + 3) values): the
 * Morton code of the origin on a grid of 2^RTCL_SORT_ORIGIN_BITS cells per
 * axis over the box [lo, lo + 2^RTCL_SORT_ORIGIN_BITS / scale] (origins
 * outside clamp to its faces, NaN to cell 0), then the direction's octant
 * (its three sign bits, -0 counted negative) in the low bits. Any ray, valid
 * or not, gets a key in range.
 *
 * Three passes over C chunks of `chunk` consecutive rays (one work-item a
 * chunk, C = the global size of ray_sort_count and ray_sort_scatter):
 *   ray_sort_count   keys[i] = ray i's key; counts[c * BUCKETS + b] = rays
 *                    of chunk c with key b
 *   ray_sort_offsets per bucket, the exclusive prefix sum over the chunks
 *                    and the bucket's total (one work-item a bucket)
 *   ray_sort_scatter each chunk writes its ray indices, in their order, from
 *                    its start in each bucket on: order[k] = i
 * Equal keys keep their input order, so the order is a function of the rays
 * alone. */
#include "shared/layouts.h"

#ifndef RTCL_SORT_ORIGIN_BITS
#define RTCL_SORT_ORIGIN_BITS 3
#endif
#define RTCL_SORT_BUCKETS (1u << (3 * RTCL_SORT_ORIGIN_BITS + 3)) /* at most 2^15: keys are ushort */

/* The bits of x (< 32) spread three apart: bit i to bit 3i. */
inline __attribute__((always_inline)) uint ray_sort_spread3(uint x) {
  return (x & 1u) | (x & 2u) << 2 | (x & 4u) << 4 | (x & 8u) << 6 | (x & 16u) << 8;
}

/* Inlined: called, the ray would cross the call through the stack, which
 * slows the count pass markedly on PoCL. */
inline __attribute__((always_inline)) uint ray_sort_key(global const Ray* r, float4 lo, float4 scale) {
  const uint top = (1u << RTCL_SORT_ORIGIN_BITS) - 1u;
  uint x = min(top, convert_uint_sat((r->ox - lo.x) * scale.x));
  uint y = min(top, convert_uint_sat((r->oy - lo.y) * scale.y));
  uint z = min(top, convert_uint_sat((r->oz - lo.z) * scale.z));
  uint origin = ray_sort_spread3(x) << 2 | ray_sort_spread3(y) << 1 | ray_sort_spread3(z);
  uint octant = (as_uint(r->dx) >> 31) << 2 | (as_uint(r->dy) >> 31) << 1 | (as_uint(r->dz) >> 31);
  return origin << 3 | octant;
}

kernel void ray_sort_count(global const Ray* rays, uint ray_count, uint chunk, float4 lo, float4 scale,
                           global uint* counts, global ushort* keys) {
  uint c = get_global_id(0);
  uint row[RTCL_SORT_BUCKETS];
  for (uint b = 0; b < RTCL_SORT_BUCKETS; ++b) row[b] = 0;
  uint begin = c * chunk, end = min(begin + chunk, ray_count);
  for (uint i = begin; i < end; ++i) {
    uint key = ray_sort_key(rays + i, lo, scale);
    keys[i] = (ushort)key;
    ++row[key];
  }
  global uint* out = counts + (size_t)c * RTCL_SORT_BUCKETS;
  for (uint b = 0; b < RTCL_SORT_BUCKETS; ++b) out[b] = row[b];
}

/* One work-item per bucket b: counts[c * BUCKETS + b] becomes the rays of
 * bucket b in the chunks before c, totals[b] the rays of bucket b. */
kernel void ray_sort_offsets(global uint* counts, uint chunks, global uint* totals) {
  uint b = get_global_id(0);
  uint running = 0;
  for (uint c = 0; c < chunks; ++c) {
    size_t at = (size_t)c * RTCL_SORT_BUCKETS + b;
    uint n = counts[at];
    counts[at] = running;
    running += n;
  }
  totals[b] = running;
}

/* Each chunk's start in bucket b: the rays of the buckets before b, plus its
 * offset within bucket b. */
kernel void ray_sort_scatter(global const ushort* keys, uint ray_count, uint chunk,
                             global const uint* offsets, global const uint* totals, global uint* order) {
  uint c = get_global_id(0);
  uint row[RTCL_SORT_BUCKETS];
  global const uint* in = offsets + (size_t)c * RTCL_SORT_BUCKETS;
  uint before = 0;
  for (uint b = 0; b < RTCL_SORT_BUCKETS; ++b) {
    row[b] = before + in[b];
    before += totals[b];
  }
  uint begin = c * chunk, end = min(begin + chunk, ray_count);
  for (uint i = begin; i < end; ++i) order[row[keys[i]]++] = i;
}
