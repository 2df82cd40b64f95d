/* 8-wide BVH traversal, one packet of 8 consecutive rays per work-item: the
 * same BVH8 as accel/bvh.cl (same build, same node and block layout), but the
 * float8 lanes hold the eight rays instead of a node's eight children
 * (packet traversal, Wald, Slusallek, Benthin, Wagner 2001, "Interactive
 * rendering with coherent ray tracing"), in one of two ways:
 *  - as one frustum (bvh_frustum_walk) when the packet's valid rays
 *    share a direction octant, have finite reciprocals and tmin >= 0: a
 *    node's eight child boxes in one float8 test against bounds of all
 *    eight rays, as a single ray's; at a leaf the rays (those that enter
 *    its box, where their origins differ) test the triangles whose boxes
 *    the frustum meets;
 *  - ray by ray in the lanes otherwise: per node, each child box is tested
 *    against the packet's rays at once; per leaf, each primitive is tested
 *    against them at once. The packet shares one stack; each entry carries
 *    the per-ray entry distances of its box, NaN for the rays that missed
 *    it, so that a popped entry is active exactly for the rays that entered
 *    its box before their current closest hit.
 *
 * Contract: rays 8p .. 8p+7 (those below ray_count) form packet p; any rays
 * work (coherent ones, e.g. screen tiles or Morton order, are faster). Every
 * ray gets exactly the arithmetic of accel/bvh.cl (shared/box.h,
 * shared/triangle.h, shared/sphere.h) at every precision level: the same
 * slab distances and the same triangle tests, lane by lane, so closest-hit
 * t is bit-identical to the single-ray kernel (at the robust and fast levels
 * the primitive may differ between two at exactly the same t; at the exact
 * level the smaller id wins there too). At the fast level, whose slab tests
 * are not widened, a hit on a triangle that lies on a box's face may be
 * found by one kernel and not the other (the frustum visits boxes a ray's
 * own test rejects). Any hit reports some hit.
 *
 * Stack bound: as in accel/bvh.cl (a node pushes at most its children and
 * pops one), so the host's RTCL_STACK_SIZE is valid here too, for both ways. */
/* What the frustum traversal pushes (bvh_frustum_walk) */
#define RTCL_BVH8_ENTRY(k) (loose ? 8 * ref + (k) : node->child[k])
#include "shared/bvh8_stack.h"
#include "shared/packet.h"

#ifndef RTCL_STACK_SIZE
#define RTCL_STACK_SIZE 64
#endif

/* Child c's box against the packet over [tmin, t_best]: rtcl_slabs8, the
 * arithmetic of intersect_boxes8, per lane (entry plane chosen by the
 * lane's direction sign).
 * Returns the entry distances, NaN where the ray misses the box (tested by
 * bits, rtcl_not_nan8: -cl-fast-relaxed-math at the fast level lets the
 * compiler fold tn == tn to true). */
inline float8 packet_box(global const Bvh8Node* node, int c, const TracePacket* p, float8 t_best, int8 mask) {
  float lx = node->bounds[0][c], ly = node->bounds[1][c], lz = node->bounds[2][c];
  float ux = node->bounds[3][c], uy = node->bounds[4][c], uz = node->bounds[5][c];
  float8 tn, tf;
  rtcl_slabs8(select((float8)(ux), (float8)(lx), p->pos_x), select((float8)(uy), (float8)(ly), p->pos_y),
              select((float8)(uz), (float8)(lz), p->pos_z), select((float8)(lx), (float8)(ux), p->pos_x),
              select((float8)(ly), (float8)(uy), p->pos_y), select((float8)(lz), (float8)(uz), p->pos_z), p->ox,
              p->oy, p->oz, p->ix, p->iy, p->iz, p->tmin, t_best, &tn, &tf);
  return select((float8)(NAN), tn, mask & (tn <= tf));
}

/* Triangle k of a block against the packet (packet_triangle_at). */
inline int8 packet_triangle(global const TriangleBlock* block, int k, const TracePacket* p, PacketHits* h,
                            int8 mask) {
  return packet_triangle_at(&block->v[0][0][k], RTCL_BLOCK_WIDTH, block->prim[k], p, h, mask);
}

/* The packet as one frustum (after Embree's traversal of coherent
 * packets): when its active rays move the same way along each axis (one
 * direction octant), have finite reciprocals and tmin >= 0, a node's eight
 * child boxes are tested against bounds of all its rays at once
 * (rtcl_frustum_slabs8: the origins' box, the reciprocals' range), one
 * float8 test per node as for a single ray, where the per-ray traversal
 * tests each child against the eight rays in turn. The test is
 * conservative (a box it rejects no ray enters), leaves test every ray
 * with its own arithmetic, and a ray's closest hit does not depend on
 * which extra boxes were visited: the hits are the per-ray traversal's.
 * Children are pushed nearest first by the frustum's entry distance
 * (shared/bvh8_stack.h, as accel/bvh.cl), the nearest visited next without
 * the stack; an entry beyond every ray's current best hit is skipped. */
typedef struct PacketFrustum {
  float onx, ony, onz;          /* origin bound for the entry planes */
  float ofx, ofy, ofz;          /* ... for the exit planes */
  float rnx, rny, rnz;          /* reciprocal direction of least magnitude per axis */
  float rfx, rfy, rfz;          /* ... of greatest magnitude */
  float tmin;                   /* the active rays' smallest tmin (>= 0) */
  int loose;                    /* the rays' origins differ */
  int near_x, near_y, near_z, far_x, far_y, far_z; /* bounds rows, as in TraceRay */
} PacketFrustum;

/* Min / max of v over `lanes` (+inf / -inf for none); never NaN here. */
inline float packet_min(float8 v, int8 lanes) { return rtcl_min8_ordered(select((float8)(INFINITY), v, lanes)); }
inline float packet_max(float8 v, int8 lanes) { return rtcl_max8_ordered(select((float8)(-INFINITY), v, lanes)); }

/* The range of v over `lanes`: max into *first and min into *second when
 * high_first, else the other way round. */
inline void packet_range(float8 v, int8 lanes, int high_first, float* first, float* second) {
  float lo = packet_min(v, lanes), hi = packet_max(v, lanes);
  *first = high_first ? hi : lo;
  *second = high_first ? lo : hi;
}

/* Fills *f and returns 1 when the packet's active rays share a direction
 * octant, have finite reciprocals and tmin >= 0, else returns 0. */
inline int packet_frustum(const TracePacket* p, PacketFrustum* f) {
  int8 a = p->active;
  int8 finite = rtcl_is_finite8(p->ix) & rtcl_is_finite8(p->iy) & rtcl_is_finite8(p->iz);
  if (rtcl_any8(a & ~finite)) return 0;
  int pos_x = rtcl_any8(a & p->pos_x), pos_y = rtcl_any8(a & p->pos_y), pos_z = rtcl_any8(a & p->pos_z);
  if ((pos_x && rtcl_any8(a & ~p->pos_x)) || (pos_y && rtcl_any8(a & ~p->pos_y)) ||
      (pos_z && rtcl_any8(a & ~p->pos_z)))
    return 0;
  packet_range(p->ox, a, pos_x, &f->onx, &f->ofx);
  packet_range(p->oy, a, pos_y, &f->ony, &f->ofy);
  packet_range(p->oz, a, pos_z, &f->onz, &f->ofz);
  f->tmin = packet_min(p->tmin, a);
  if (!(f->tmin >= 0.0f)) return 0;
  f->loose = f->onx != f->ofx || f->ony != f->ofy || f->onz != f->ofz;
  packet_range(p->ix, a, !pos_x, &f->rnx, &f->rfx);
  packet_range(p->iy, a, !pos_y, &f->rny, &f->rfy);
  packet_range(p->iz, a, !pos_z, &f->rnz, &f->rfz);
  f->near_x = pos_x ? 0 : 3;
  f->near_y = pos_y ? 1 : 4;
  f->near_z = pos_z ? 2 : 5;
  f->far_x = 3 - f->near_x;
  f->far_y = 5 - f->near_y;
  f->far_z = 7 - f->near_z;
  return 1;
}

/* The triangles of a block whose boxes the frustum meets (a bit per lane):
 * their boxes, from the block's own vertex rows (min / max: exact), under
 * the node boxes' test, so no triangle a ray of the packet hits is left
 * out. */
inline int frustum_triangles(global const TriangleBlock* block, const PacketFrustum* f, float tmax) {
  float8 lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    float8 v0 = vload8(0, block->v[0][a]), v1 = vload8(0, block->v[1][a]), v2 = vload8(0, block->v[2][a]);
    lo[a] = fmin(v0, fmin(v1, v2));
    hi[a] = fmax(v0, fmax(v1, v2));
  }
  float8 tn, tf;
  rtcl_frustum_slabs8(f->near_x == 0 ? lo[0] : hi[0], f->near_y == 1 ? lo[1] : hi[1], f->near_z == 2 ? lo[2] : hi[2],
                      f->near_x == 0 ? hi[0] : lo[0], f->near_y == 1 ? hi[1] : lo[1], f->near_z == 2 ? hi[2] : lo[2],
                      f->onx, f->ony, f->onz, f->ofx, f->ofy, f->ofz, f->rnx, f->rny, f->rnz, f->rfx, f->rfy, f->rfz,
                      f->tmin, tmax, &tn, &tf);
  return rtcl_lane_bits8((tn <= tf) & (vload8(0, block->prim) >= 0));
}

/* The leaf `leaf` (a node reference's complement) against the packet's
 * rays in `mask`; with a frustum (else null), only the triangles whose
 * boxes it meets. Any hit: the rays that hit leave `alive` and `mask`. */
inline void packet_leaf(int leaf, const TracePacket* p, const PacketFrustum* f, PacketHits* h,
                        global const TriangleBlock* triangles, global const SphereBlock* spheres, int8* alive,
                        int8* mask) {
#ifdef RTCL_HAS_SPHERES
  if (leaf & 1) {
    global const SphereBlock* block = spheres + (leaf >> 1);
    for (int k = 0; k < RTCL_BLOCK_WIDTH; ++k) {
      if (block->prim[k] < 0) continue;
      int8 hit = packet_sphere(block, k, p, h, *mask);
      if (RTCL_ANY_HIT) {
        *alive &= ~hit;
        *mask &= ~hit;
      }
    }
    return;
  }
#endif
  global const TriangleBlock* block = triangles + (leaf >> 1);
  int lanes = 0xff;
  if (f) lanes = frustum_triangles(block, f, packet_max(h->t_best, *mask));
  for (int k = 0; k < RTCL_BLOCK_WIDTH; ++k) {
    if (!(lanes >> k & 1) || block->prim[k] < 0) continue;
    int8 hit = packet_triangle(block, k, p, h, *mask);
    if (RTCL_ANY_HIT) {
      *alive &= ~hit;
      *mask &= ~hit;
    }
  }
}

/* The frustum traversal; `loose` (a constant in each caller) when the
 * rays' origins differ: then the frustum holds far more than the rays,
 * and a leaf's rays are first tested against its own box (per ray, as the
 * per-ray traversal does), for which the stack holds child slots
 * (8 * node + lane). Tight frusta (one origin) skip that test: a triangle
 * a ray hits lies in a box the ray enters, so the hits are the same.
 * Returns the last leaf that blocked rays of the packet (any hit), else -1. */
RTCL_LANES_INLINE int bvh_frustum_walk(const TracePacket* p, const PacketFrustum* f, PacketHits* h,
                                       global const Bvh8Node* nodes, global const TriangleBlock* triangles,
                                       global const SphereBlock* spheres, const int loose) {
  const PacketFrustum fr = *f; /* in registers: the stack's stores do not reload it */
  int stack_ref[RTCL_STACK_SIZE]; /* child references (tight) or slots (loose) */
  float stack_t[RTCL_STACK_SIZE]; /* the frustum's entry distance of the entry's box */
  int sp = 0;
  int ref = 0, slot = 0;
  int8 alive = p->active; /* any hit: rays still looking */
  int blocker = -1;
  float t_far = packet_max(h->t_best, alive); /* beyond every alive ray's best hit: changes at leaves only */
  for (;;) {
    if (ref >= 0) {
      global const Bvh8Node* node = nodes + ref;
      global const float8* b = (global const float8*)node->bounds;
      float8 t_entry, t_exit;
      rtcl_frustum_slabs8(b[fr.near_x], b[fr.near_y], b[fr.near_z], b[fr.far_x], b[fr.far_y], b[fr.far_z], fr.onx,
                          fr.ony, fr.onz, fr.ofx, fr.ofy, fr.ofz, fr.rnx, fr.rny, fr.rnz, fr.rfx, fr.rfy, fr.rfz, fr.tmin,
                          t_far, &t_entry, &t_exit);
      int8 hit = t_entry <= t_exit;
      if (rtcl_any8(hit)) {
        RTCL_BVH8_PUSH_CHILDREN_BUT_NEAREST
        slot = near_entry;
        ref = loose ? node->child[slot & 7] : slot;
        continue;
      }
    } else {
      int8 before = alive, mask = alive;
      if (loose) mask = rtcl_not_nan8(packet_box(nodes + (slot >> 3), slot & 7, p, h->t_best, alive));
      if (rtcl_any8(mask)) {
        packet_leaf(~ref, p, f, h, triangles, spheres, &alive, &mask);
        if (RTCL_ANY_HIT && rtcl_any8(before & ~alive)) {
          blocker = ~ref;
          if (!rtcl_any8(alive)) return blocker;
        }
        t_far = packet_max(h->t_best, alive);
      }
    }
    do {
      if (sp == 0) return blocker;
      --sp;
    } while (!RTCL_ANY_HIT && stack_t[sp] > t_far);
    slot = stack_ref[sp];
    ref = loose ? nodes[slot >> 3].child[slot & 7] : slot;
  }
}

__attribute__((noinline)) int bvh_frustum_traverse_tight(const TracePacket* p, const PacketFrustum* f, PacketHits* h,
                                                          global const Bvh8Node* nodes,
                                                          global const TriangleBlock* triangles,
                                                          global const SphereBlock* spheres) {
  return bvh_frustum_walk(p, f, h, nodes, triangles, spheres, 0);
}

__attribute__((noinline)) int bvh_frustum_traverse_loose(const TracePacket* p, const PacketFrustum* f, PacketHits* h,
                                                          global const Bvh8Node* nodes,
                                                          global const TriangleBlock* triangles,
                                                          global const SphereBlock* spheres) {
  return bvh_frustum_walk(p, f, h, nodes, triangles, spheres, 1);
}

/* Traverses the packet: as one frustum when packet_frustum allows, else
 * ray by ray in the lanes. Any hit: a ray leaves the packet at its first
 * hit; the traversal ends when every ray has. Returns the last leaf that
 * blocked rays (any hit), else -1. */
__attribute__((noinline)) int bvh_packet_traverse(const TracePacket* p, PacketHits* h, global const Bvh8Node* nodes,
                                                   global const TriangleBlock* triangles,
                                                   global const SphereBlock* spheres) {
  PacketFrustum frustum;
  if (packet_frustum(p, &frustum))
    return frustum.loose ? bvh_frustum_traverse_loose(p, &frustum, h, nodes, triangles, spheres)
                         : bvh_frustum_traverse_tight(p, &frustum, h, nodes, triangles, spheres);
  float8 stack_t[RTCL_STACK_SIZE]; /* entry distances of stack_ref's box, NaN: ray not in it */
  int stack_ref[RTCL_STACK_SIZE];
  float stack_key[RTCL_STACK_SIZE]; /* nearest entry distance over the packet: visiting order */
  int sp = 0;
  int ref = 0;
  int8 alive = p->active; /* any hit: rays still looking */
  int8 mask = alive;
  int blocker = -1;
  for (;;) {
    if (ref >= 0) {
      global const Bvh8Node* node = nodes + ref;
      int base = sp;
      for (int c = 0; c < 8; ++c) {
        int child = node->child[c];
        if (child == RTCL_CHILD_EMPTY) continue;
        float8 tn = packet_box(node, c, p, h->t_best, mask);
        int8 in = rtcl_not_nan8(tn);
        if (!rtcl_any8(in)) continue;
        float key = rtcl_min8(select((float8)(INFINITY), tn, in));
        /* insertion into [base, sp) kept sorted by decreasing key */
        int j = sp++;
        while (!RTCL_ANY_HIT && j > base && stack_key[j - 1] < key) {
          stack_key[j] = stack_key[j - 1];
          stack_t[j] = stack_t[j - 1];
          stack_ref[j] = stack_ref[j - 1];
          --j;
        }
        stack_key[j] = key;
        stack_t[j] = tn;
        stack_ref[j] = child;
      }
    } else {
      int8 before = alive;
      packet_leaf(~ref, p, 0, h, triangles, spheres, &alive, &mask);
      if (RTCL_ANY_HIT && rtcl_any8(before & ~alive)) {
        blocker = ~ref;
        if (!rtcl_any8(alive)) return blocker;
      }
    }
    /* pop the next entry some ray still needs: entered before its best hit */
    for (;;) {
      if (sp == 0) return blocker;
      --sp;
      mask = alive & (stack_t[sp] <= h->t_best);
      if (rtcl_any8(mask)) break;
    }
    ref = stack_ref[sp];
  }
}

#define BVH_PACKET_PARAMS global const Bvh8Node *nodes, global const TriangleBlock *triangles, global const SphereBlock *spheres
#define BVH_PACKET_ARGS nodes, triangles, spheres
/* Leaf `leaf` against the packet's active rays (any hit); the rays it blocks. */
inline int8 bvh_packet_leaf(int leaf, const TracePacket* p, PacketHits* h, BVH_PACKET_PARAMS) {
  int8 alive = p->active, mask = p->active;
  packet_leaf(leaf, p, 0, h, triangles, spheres, &alive, &mask);
  return p->active & ~alive;
}
RTCL_PACKET_KERNELS_OCCLUDER_CACHE(bvh_packet, BVH_PACKET_PARAMS, BVH_PACKET_ARGS)
