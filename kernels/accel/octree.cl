/* Octree traversal by node-code matching, one ray per work-item: the
 * lecture's 光线跟踪过程 (空间八叉树剖分技术), on the code table of
 * OctreeHeader (kernels/shared/layouts.h); no node pointers on the device.
 *
 * Everything is located in the integer lattice 0 .. 2^N per axis. For the
 * current point P (lattice coordinates x, y, z):
 *   1. its code Q = q1 .. qN, q_l = i_l + 2 j_l + 4 k_l from the bits of
 *      x, y, z (property 1), built by spreading the bits four apart;
 *   2. the longest match of Q in the sorted leaf table gives T (a leaf with
 *      primitives holds P) and i (matching leading digits): the leaf whose
 *      code is the first not below Q holds P exactly when its digits after
 *      the match are all F (codes of a subtree are contiguous, and a leaf's
 *      F padding sorts after every code below it); otherwise the longest
 *      match is with that leaf or the one before it, and P lies in the empty
 *      cell of level i + 1;
 *   3. the cell's lower corner is P with its last N - level bits cleared
 *      (property 2), its side 2^(N - level) lattice units;
 *   4. for T, the leaf's primitives are tested; the walk ends once the
 *      closest hit lies inside the cell (as the grid's: t_best <= the cell's
 *      exit distance less a conservative margin);
 *   5. the exit point: the exit distance through each of the cell's six
 *      faces from the ray's per-axis slope (reciprocal direction) and
 *      intercept (origin), the nearest taken (x before y before z on ties);
 *      the next point is one lattice step past that face on the exit axis,
 *      and on the other axes the exit point's lattice coordinate, clamped
 *      into the current cell and never moved against the ray's direction.
 *      Every coordinate is thus monotone along the ray and the exit axis
 *      advances by at least one: no cell is repeated, and the walk ends
 *      within 3 * 2^N steps; a cell is entered through the face it shares
 *      with the last one, so none the ray crosses is skipped (an exit
 *      through an edge or corner visits the face neighbours in between, for
 *      an empty interval).
 * A start point on a lattice plane belongs to the cell the ray moves into
 * (floor for a positive or zero direction component, ceil - 1 for a
 * negative one), clamped into the cube that the ray's clipped interval
 * meets.
 *
 * The lookup (step 2) is the cost centre: a lower bound by binary search,
 * narrowed first by the bucket table over the first top_digits digits
 * (the prefix selects one bucket of the sorted table, ~2 leaves on
 * average), so that a lookup reads a few codes instead of log2(leaves)
 * (option buckets; without it, the binary search alone).
 *
 * A leaf's primitives are its own blocks (octree_test_leaf: brute force's
 * block tests, the same t bit for bit). */
#include "shared/octree.h"

/* Lattice plane n on one axis (OctreeHeader contract; the host builds with
 * the same expression, src/rtcl/accel/octree.cpp). */
inline float octree_plane(float lower, float cell, uint n) { return lower + (float)n * cell; }

/* The low 16 bits of v, bit b moved to bit 4b. */
inline ulong octree_spread(uint v) {
  ulong x = v & 0xffffu;
  x = (x | (x << 24)) & 0x000000ff000000ffUL;
  x = (x | (x << 12)) & 0x000f000f000f000fUL;
  x = (x | (x << 6)) & 0x0303030303030303UL;
  x = (x | (x << 3)) & 0x1111111111111111UL;
  return x;
}

/* Property 1: the code of the unit cell at lattice point (x, y, z). */
inline ulong octree_point_code(uint x, uint y, uint z) {
  return octree_spread(x) | (octree_spread(y) << 1) | (octree_spread(z) << 2);
}

/* Leading digits two N-digit codes share (N when equal). */
inline int octree_match(ulong a, ulong b, int depth) {
  ulong x = a ^ b;
  return x == 0 ? depth : ((int)clz(x) - (64 - 4 * depth)) >> 2;
}

/* Step 2: the level of the cell holding the point of code q, and in *leaf
 * the table index of its leaf when it holds primitives (else -1). */
inline int octree_lookup(ulong q, const OctreeHeader* g, global const ulong* codes,
                         global const uint* bucket_begin, int* leaf) {
  const int n = g->depth;
  uint b = 0;
  for (int l = 0; l < g->top_digits; ++l) b = (b << 3) | (uint)((q >> (4 * (n - 1 - l))) & 7);
  uint lo = bucket_begin[b], count = bucket_begin[b + 1] - lo;
  while (count > 0) { /* lower bound: the first code >= q */
    uint mid = count >> 1;
    if (codes[lo + mid] < q) {
      lo += mid + 1;
      count -= mid + 1;
    } else {
      count = mid;
    }
  }
  int matched = 0;
  if (lo < g->leaf_count) {
    ulong c = codes[lo];
    matched = octree_match(q, c, n);
    int rest = 4 * (n - matched);
    ulong pad = rest >= 64 ? ~0UL : ((1UL << rest) - 1UL);
    if ((c & pad) == pad) {
      *leaf = (int)lo;
      return matched;
    }
  }
  if (lo > 0) matched = max(matched, octree_match(q, codes[lo - 1], n));
  *leaf = -1;
  return matched + 1;
}

/* The lattice coordinate of float position p on one axis, for a ray moving
 * with sign `step` (a point on a plane goes to the side it moves into). */
inline float octree_lattice(float p, float lower, float cell, int step) {
  float x = (p - lower) / cell;
  return step < 0 ? ceil(x) - 1.0f : floor(x);
}

/* Returns the leaf (its table index) that ended an any-hit traversal, else
 * -1. */
__attribute__((noinline)) int octree_traverse(const TraceRay* s, HitState* h, global const OctreeHeader* header,
                                              global const ulong* codes, global const uint* leaf_begin,
                                              global const uint* bucket_begin, global const TriangleBlock* triangles,
                                              global const SphereBlock* spheres, global const BlockBox* boxes) {
  const OctreeHeader g = *header;
  if (g.leaf_count == 0) return -1;
  const uint side = 1u << g.depth;
  const float o[3] = {s->ox, s->oy, s->oz}, d[3] = {s->dx, s->dy, s->dz}, inv[3] = {s->ix, s->iy, s->iz};
  float t0 = s->tmin, t1 = s->tmax;
  int step[3];
  for (int a = 0; a < 3; ++a)
    if (!octree_clip_axis(o[a], d[a], inv[a], g.lower[a], octree_plane(g.lower[a], g.cell, side), &t0, &t1,
                          &step[a]))
      return -1;
  if (!(t0 <= t1)) return -1;
  uint p[3];
  for (int a = 0; a < 3; ++a) {
    float x = octree_lattice(step[a] == 0 ? o[a] : o[a] + t0 * d[a], g.lower[a], g.cell, step[a]);
    p[a] = (uint)clamp(x, 0.0f, (float)(side - 1));
  }
  for (;;) {
    int leaf;
    int level = octree_lookup(octree_point_code(p[0], p[1], p[2]), &g, codes, bucket_begin, &leaf);
    if (leaf >= 0 && octree_test_leaf((uint)leaf, leaf_begin, triangles, spheres, boxes, s, h)) return leaf;
    /* property 2: the cell's lower corner and side */
    const uint size = 1u << (g.depth - level);
    uint lower[3];
    float t_exit[3];
    for (int a = 0; a < 3; ++a) {
      lower[a] = p[a] & ~(size - 1u);
      t_exit[a] = step[a] == 0 ? FLT_MAX
                               : (octree_plane(g.lower[a], g.cell, lower[a] + (step[a] > 0 ? size : 0u)) - o[a]) *
                                     inv[a];
    }
    int axis = (t_exit[0] <= t_exit[1] && t_exit[0] <= t_exit[2]) ? 0 : (t_exit[1] <= t_exit[2] ? 1 : 2);
    float te = t_exit[axis];
    if (h->t_best <= te - fabs(te) * RTCL_SLAB_WIDEN) return -1;
    if (step[axis] == 0) return -1;
    /* the next point: one step past the exit face, the others from the exit
     * point, clamped into this cell and monotone */
    for (int a = 0; a < 3; ++a) {
      if (a == axis || step[a] == 0) continue;
      float x = octree_lattice(o[a] + te * d[a], g.lower[a], g.cell, step[a]);
      float lo = (float)(step[a] > 0 ? p[a] : lower[a]);
      float hi = (float)(step[a] > 0 ? lower[a] + size - 1u : p[a]);
      p[a] = (uint)clamp(x, lo, hi);
    }
    if (step[axis] > 0) {
      p[axis] = lower[axis] + size;
      if (p[axis] >= side) return -1;
    } else {
      if (lower[axis] == 0) return -1;
      p[axis] = lower[axis] - 1u;
    }
  }
}

#define OCTREE_PARAMS                                                                                  \
  global const OctreeHeader *header, global const ulong *codes, global const uint *leaf_begin,         \
      global const uint *bucket_begin, global const TriangleBlock *triangles, global const SphereBlock *spheres, \
      global const BlockBox *boxes
#define OCTREE_ARGS header, codes, leaf_begin, bucket_begin, triangles, spheres, boxes
/* Leaf `leaf` (its table index) against the ray; whether it hit (any hit). */
inline int octree_leaf(int leaf, const TraceRay* s, HitState* h, OCTREE_PARAMS) {
  return octree_test_leaf((uint)leaf, leaf_begin, triangles, spheres, boxes, s, h);
}
RTCL_TRACE_KERNELS_OCCLUDER_CACHE(octree, OCTREE_PARAMS, OCTREE_ARGS)
