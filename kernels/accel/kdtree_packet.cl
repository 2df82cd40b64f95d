/* kd-tree (and BSP) traversal in packets of 8 rays, one packet per
 * work-item, the rays in float8 lanes (Wald, Slusallek, Benthin, Wagner
 * 2001; Wald 2004, ch. 7): the same nodes and reference lanes as
 * accel/kdtree.cl, and per lane exactly its decisions.
 *
 * Each lane carries its own interval [t0, t1] (NaN: the lane is not in the
 * current subtree). At an inner node each lane computes dist, its near
 * side and whether its interval reaches the below child, the above child or
 * both (accel/kdtree.cl's rules: zero direction component, origin on the
 * plane, ray lying in the plane, the conservative widening). The packet
 * descends into a child without a push when no lane needs the other one;
 * otherwise it pushes the other child with the per-lane intervals of the
 * lanes that need it (NaN elsewhere) and descends. Lanes whose direction
 * signs differ on the split axis have different near sides: the packet
 * visits first the child that is near for most of its lanes; the others
 * visit their far side first, which costs them only the early exit (every
 * lane keeps its closest hit over all the leaves it visits, so the visiting
 * order never changes the answer). Empty leaves are neither visited nor
 * pushed when the other child is needed.
 *
 * Leaves: each reference is tested against the packet's lanes at once
 * (packet_triangle_at, packet_sphere: the single-ray arithmetic per lane),
 * so closest-hit t is bit-identical to accel/kdtree.cl and brute force.
 * Early exit per lane: a lane leaves a subtree (at its pop, and at every
 * node) once its closest hit lies before the subtree's interval,
 * t_best <= t0 - |t0| * KD_EXIT_MARGIN; the packet ends when no lane is
 * left. Any hit: a lane leaves at its first hit.
 *
 * Contract: rays 8p .. 8p+7 (those below ray_count) form packet p; any rays
 * work, coherent ones (screen tiles, Morton order) are faster.
 *
 * Stack bound: an entry is pushed only at an inner node whose two children
 * are both needed, and holds the child not descended into: the entries are
 * children of distinct ancestors of the current node, one per depth, so at
 * most depth(tree) <= RTCL_KD_STACK, as in accel/kdtree.cl. */
#include "shared/kdtree.h"
#include "shared/packet.h"

/* One axis of the root box against the packet, per lane: [t0, t1] narrowed
 * to the slab (widened by RTCL_SLAB_WIDEN, Ize 2013); a lane that does not
 * move along the axis keeps its interval when its origin is within the
 * slab. Returns the lanes whose ray meets the slab. */
inline int8 kdp_clip_axis(float8 o, float8 d, float8 inv, float lower, float upper, float8* t0, float8* t1) {
  int8 flat = (d == 0.0f) | !isfinite(inv);
  int8 pos = d > 0.0f;
  float8 tn = (select((float8)(upper), (float8)(lower), pos) - o) * inv;
  float8 tf = (select((float8)(lower), (float8)(upper), pos) - o) * inv;
  *t0 = select(fmax(*t0, tn - fabs(tn) * RTCL_SLAB_WIDEN), *t0, flat);
  *t1 = select(fmin(*t1, tf + fabs(tf) * RTCL_SLAB_WIDEN), *t1, flat);
  return select((int8)(-1), (o >= lower) & (o <= upper), flat);
}

/* Lanes whose closest hit lies before their interval [t0, ...): done. */
inline int8 kdp_live(float8 t0, float8 t_best) {
  return (t0 == t0) & !(t_best <= t0 - fabs(t0) * KD_EXIT_MARGIN);
}

/* Number of set lanes of a mask. */
inline int kdp_count(int8 m) {
  int8 one = m & (int8)(1);
  int4 a = one.lo + one.hi;
  int2 b = a.lo + a.hi;
  return b.x + b.y;
}

__attribute__((noinline)) void kdtree_packet_traverse(const TracePacket* p, PacketHits* h,
                                                      global const KdHeader* header, global const KdNode* nodes,
                                                      global const int* refs, global const float* lanes,
                                                      global const int* lane_prims,
                                                      global const SphereBlock* spheres) {
  const int lane_stride = header->lane_stride;
  float8 t0 = p->tmin, t1 = p->tmax;
  int8 ok = p->active;
  ok &= kdp_clip_axis(p->ox, p->dx, p->ix, header->lower[0], header->upper[0], &t0, &t1);
  ok &= kdp_clip_axis(p->oy, p->dy, p->iy, header->lower[1], header->upper[1], &t0, &t1);
  ok &= kdp_clip_axis(p->oz, p->dz, p->iz, header->lower[2], header->upper[2], &t0, &t1);
  ok &= t0 <= t1;
  if (!rtcl_any8(ok)) return;
  t0 = select((float8)(NAN), t0, ok);
  t1 = select((float8)(NAN), t1, ok);
  int8 alive = ok; /* any hit: lanes still looking */
  uint stack_node[RTCL_KD_STACK];
  float8 stack_t0[RTCL_KD_STACK], stack_t1[RTCL_KD_STACK];
  int top = 0;
  uint n = 0;
  for (;;) {
    KdNode node = nodes[n];
    uint axis = node.flags & 3u;
    if (axis != RTCL_KD_LEAF) {
      float8 o = axis == 0 ? p->ox : (axis == 1 ? p->oy : p->oz);
      float8 d = axis == 0 ? p->dx : (axis == 1 ? p->dy : p->dz);
      float8 inv = axis == 0 ? p->ix : (axis == 1 ? p->iy : p->iz);
      float8 delta = (float8)(as_float(node.data)) - o;
      float8 dist = delta * inv;
      uint below = n + 1, above = node.flags >> 2;
      int8 live = kdp_live(t0, h->t_best);
      int8 below_near = (delta > 0.0f) | ((delta == 0.0f) & (d > 0.0f));
      int8 plane = dist != dist; /* in the plane: both, each over the whole interval */
      int8 near_only = ~plane & ((dist < 0.0f) | (dist * (1.0f - RTCL_SLAB_WIDEN) > t1));
      int8 far_only = ~plane & ~near_only & (dist * (1.0f + RTCL_SLAB_WIDEN) < t0);
      int8 both = live & ~near_only & ~far_only;
      near_only &= live;
      far_only &= live;
      int8 cut = both & ~plane;
      float8 near_t1 = select(t1, fmin(t1, dist), cut);
      float8 far_t0 = select(t0, fmax(t0, dist), cut);
      int8 want_below = select(far_only | both, near_only | both, below_near);
      int8 want_above = select(near_only | both, far_only | both, below_near);
      int go_below = rtcl_any8(want_below), go_above = rtcl_any8(want_above);
      if (go_below && go_above) {
        if (KD_EMPTY(nodes[below])) go_below = 0;
        if (KD_EMPTY(nodes[above])) go_above = 0;
      }
      float8 b0 = select((float8)(NAN), select(far_t0, t0, below_near), want_below);
      float8 b1 = select((float8)(NAN), select(t1, near_t1, below_near), want_below);
      float8 a0 = select((float8)(NAN), select(t0, far_t0, below_near), want_above);
      float8 a1 = select((float8)(NAN), select(near_t1, t1, below_near), want_above);
      if (go_below && go_above) {
        int below_first = 2 * kdp_count(live & below_near) >= kdp_count(live);
        stack_node[top] = below_first ? above : below;
        stack_t0[top] = below_first ? a0 : b0;
        stack_t1[top] = below_first ? a1 : b1;
        ++top;
        n = below_first ? below : above;
        t0 = below_first ? b0 : a0;
        t1 = below_first ? b1 : a1;
        continue;
      }
      if (go_below) {
        n = below;
        t0 = b0;
        t1 = b1;
        continue;
      }
      if (go_above) {
        n = above;
        t0 = a0;
        t1 = a1;
        continue;
      }
    } else {
      uint first = node.flags >> 2, end = first + node.data;
      int8 mask = kdp_live(t0, h->t_best);
      for (uint k = first; k < end && rtcl_any8(mask); ++k) {
        int r = refs[k];
        int8 hit;
#ifdef RTCL_HAS_SPHERES
        if (r < 0)
          hit = packet_sphere(spheres + (~r >> 3), ~r & 7, p, h, mask);
        else
#endif
          hit = packet_triangle_at(lanes + k, lane_stride, lane_prims[k], p, h, mask);
        if (RTCL_ANY_HIT) {
          alive &= ~hit;
          mask &= ~hit;
        }
      }
      if (RTCL_ANY_HIT && !rtcl_any8(alive)) return;
    }
    /* The next subtree some lane still needs. */
    int8 mask;
    do {
      if (top == 0) return;
      --top;
      t0 = stack_t0[top];
      mask = alive & kdp_live(t0, h->t_best);
    } while (!rtcl_any8(mask));
    n = stack_node[top];
    t0 = select((float8)(NAN), t0, mask);
    t1 = select((float8)(NAN), stack_t1[top], mask);
  }
}

/* The argument list of accel/kdtree.cl (one for both kernels of a
 * structure); the fused nodes are the single-ray traversal's, unused here. */
#define KD_PACKET_PARAMS                                                                              \
  global const KdHeader *header, global const KdNode *nodes, global const Bvh8Node *fused, global const int *refs, \
      global const float *lanes, global const int *lane_prims, global const SphereBlock *spheres
#define KD_PACKET_ARGS header, nodes, refs, lanes, lane_prims, spheres
RTCL_PACKET_KERNELS(kdtree_packet, KD_PACKET_PARAMS, KD_PACKET_ARGS)
