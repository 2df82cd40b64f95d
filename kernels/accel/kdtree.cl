/* BSP and kd-tree traversal, one ray per work-item: the lecture's
 * RayTreeIntersect(Ray, Node, min, max) (空间二分树, "Traversal in BSP
 * Tree") with an explicit stack in place of the recursion. Both structures
 * (src/rtcl/accel/bsp.cpp: midpoint splits; kdtree.cpp: SAH splits) build
 * the same nodes (KdNode, kernels/shared/layouts.h), so this one file is
 * the kernel of both: trace_closest_kdtree / trace_any_kdtree.
 *
 * [min, max] starts as the ray's interval [tmin, tmax] clipped to the root
 * box (min < 0 when the origin is inside and tmin < 0). At an inner node
 * with split plane x[axis] = split, dist = (split - o[axis]) / d[axis] is
 * the signed distance along the ray to the plane; near is the child whose
 * half-space holds the origin, far the other one. As in the lecture:
 *   dist > max or dist < 0: the whole interval is on the near side;
 *   dist < min:             the whole interval is on the far side;
 *   otherwise:              near over [min, dist], then far over [dist, max].
 * Special cases:
 *   - a zero (or flushed) direction component: the reciprocal is ±inf, so
 *     dist = ±inf and the ray stays on the near side; the origin decides
 *     the side (below when o < split, above when o > split);
 *   - an origin on the plane (o == split): near is the side the ray comes
 *     from (below when d > 0), so dist = 0 sends t > 0 to the far side;
 *   - a ray lying in the plane (o == split and d == 0, dist = 0 * inf =
 *     NaN): both children, each over the whole interval (a primitive that
 *     touches the plane from one side may be listed on that side only);
 *   - dist exactly at min or max: both children (one of them over an empty
 *     or one-point interval).
 * Where the interval reaches both children and one of them is an empty
 * leaf (the SAH's cut-off empty space), the walk goes on with the other
 * over its part of the interval, pushing nothing.
 * The comparisons are conservative: the plane counts as inside the interval
 * when it is within RTCL_SLAB_WIDEN (relative) of it, which covers the
 * rounding of dist and of the interval ends; the intervals themselves are
 * split at the computed dist.
 *
 * Leaves: the triangles are tested from the reference lanes (KdNode) in
 * contiguous runs of up to eight (intersect_triangle_run: float8 loads, no
 * gather; sphere positions are NaN and never hit), the spheres gathered by
 * reference in batches of eight (intersect_sphere_refs): the arithmetic of
 * brute force, so the same t bit for bit. The closest hit so far stays a
 * candidate even when it lies beyond the leaf's interval (a primitive
 * extending into later leaves is then not closer when met again). Early
 * exit: a subtree on the stack is skipped when the candidate lies before
 * its interval, t_best <= its min less a conservative margin; the walk ends
 * when no subtree is left. A far child's min is the plane's dist, which is
 * the max of the near side's interval, so this is the lecture's exit once
 * the hit lies inside the current interval; a ray lying in a plane pushes
 * its far child over the same interval as the near one, and that subtree
 * is still visited. The margin, KD_EXIT_MARGIN relative, covers the
 * rounding of dist and of the hit's t: a primitive ending exactly on a
 * plane is listed on its side only, and one beyond the plane hit within
 * rounding of dist is still found. Any hit ends at the first hit.
 *
 * Stack bound (RTCL_KD_STACK, compile-time): an entry is pushed only at an
 * inner node that sends the ray to both children, and holds that node's far
 * child. The entries on the stack are far children of distinct ancestors of
 * the current node (an entry is popped before any node outside its parent's
 * subtree is visited), one per ancestor depth, so a walk that reaches a
 * node at depth k holds at most k entries, and pushes at most depth(tree)
 * in all. The host refuses trees deeper than RTCL_KD_STACK
 * (src/rtcl/accel/kdtree_nodes.cpp, kKdMaxDepth). */
#include "shared/kdtree.h"
#include "shared/trace.h"

/* One axis of the ray against the root box: narrows [*t0, *t1] to the
 * slab (conservatively widened, Ize 2013); a ray that does not move along
 * the axis limits nothing when its origin is within the slab. Returns 0
 * when the ray misses the slab. */
inline int kd_clip_axis(float o, float d, float inv, float lower, float upper, float* t0, float* t1) {
  if (d == 0.0f || !rtcl_is_finite(inv)) return o >= lower && o <= upper;
  float tn = ((d > 0.0f ? lower : upper) - o) * inv;
  float tf = ((d > 0.0f ? upper : lower) - o) * inv;
  *t0 = fmax(*t0, tn - fabs(tn) * RTCL_SLAB_WIDEN);
  *t1 = fmin(*t1, tf + fabs(tf) * RTCL_SLAB_WIDEN);
  return 1;
}

/* Tests a leaf's references refs[first .. end) (triangles, then spheres as
 * ~r): the triangles' lanes in runs of eight, the spheres in batches of
 * eight. Returns 1 when a hit ends an any-hit query. */
inline int kd_test_leaf(global const int* refs, uint first, uint end, global const float* lanes, int lane_stride,
                        global const int* lane_prims, global const SphereBlock* spheres, const TraceRay* s,
                        HitState* h) {
  for (uint k = first; k < end; k += 8)
    if (intersect_triangle_run(lanes, lane_stride, lane_prims, k, (int)min(end - k, 8u), s, h) && RTCL_ANY_HIT)
      return 1;
#ifdef RTCL_HAS_SPHERES
  int batch[8];
  int count = 0;
  uint k = first;
  while (k < end && refs[k] >= 0) ++k;
  for (; k < end; ++k) {
    batch[count++] = ~refs[k];
    if (count == 8 || k + 1 == end) {
      if (intersect_sphere_refs(spheres, batch, count, s, h) && RTCL_ANY_HIT) return 1;
      count = 0;
    }
  }
#endif
  return 0;
}

__attribute__((noinline)) void kdtree_traverse(const TraceRay* s, HitState* h, global const KdHeader* header,
                                               global const KdNode* nodes, global const int* refs,
                                               global const float* lanes, global const int* lane_prims,
                                               global const SphereBlock* spheres) {
  const int lane_stride = header->lane_stride;
  float t_min = s->tmin, t_max = s->tmax;
  if (!kd_clip_axis(s->ox, s->dx, s->ix, header->lower[0], header->upper[0], &t_min, &t_max)) return;
  if (!kd_clip_axis(s->oy, s->dy, s->iy, header->lower[1], header->upper[1], &t_min, &t_max)) return;
  if (!kd_clip_axis(s->oz, s->dz, s->iz, header->lower[2], header->upper[2], &t_min, &t_max)) return;
  if (!(t_min <= t_max)) return;
  uint stack_node[RTCL_KD_STACK];
  float stack_min[RTCL_KD_STACK], stack_max[RTCL_KD_STACK];
  int top = 0;
  uint n = 0;
  for (;;) {
    KdNode node = nodes[n];
    uint axis = node.flags & 3u;
    while (axis != RTCL_KD_LEAF) {
      float o = axis == 0 ? s->ox : (axis == 1 ? s->oy : s->oz);
      float d = axis == 0 ? s->dx : (axis == 1 ? s->dy : s->dz);
      float inv = axis == 0 ? s->ix : (axis == 1 ? s->iy : s->iz);
      float delta = as_float(node.data) - o;
      float dist = delta * inv;
      uint below = n + 1, above = node.flags >> 2;
      int below_near = delta > 0.0f || (delta == 0.0f && d > 0.0f);
      uint near = below_near ? below : above, far = below_near ? above : below;
      int both = rtcl_is_nan(dist); /* in the plane: both, each over the whole interval */
      if (!both) {
        if (dist < 0.0f || dist * (1.0f - RTCL_SLAB_WIDEN) > t_max) {
          n = near;
        } else if (dist * (1.0f + RTCL_SLAB_WIDEN) < t_min) {
          n = far;
        } else {
          both = 1;
        }
      }
      if (both) {
        /* An empty leaf on either side is not visited (nor pushed). */
        KdNode far_node = nodes[far];
        if (KD_EMPTY(far_node)) {
          if (!rtcl_is_nan(dist)) t_max = fmin(t_max, dist);
          n = near;
        } else {
          KdNode near_node = nodes[near];
          if (KD_EMPTY(near_node)) {
            if (!rtcl_is_nan(dist)) t_min = fmax(t_min, dist);
            n = far;
            node = far_node;
            axis = node.flags & 3u;
            continue;
          }
          stack_node[top] = far;
          stack_min[top] = rtcl_is_nan(dist) ? t_min : fmax(t_min, dist);
          stack_max[top] = t_max;
          ++top;
          if (!rtcl_is_nan(dist)) t_max = fmin(t_max, dist);
          n = near;
          node = near_node;
          axis = node.flags & 3u;
          continue;
        }
      }
      node = nodes[n];
      axis = node.flags & 3u;
    }
    uint first = node.flags >> 2;
    if (kd_test_leaf(refs, first, first + node.data, lanes, lane_stride, lane_prims, spheres, s, h)) return;
    /* The next subtree whose interval may still hold a nearer hit. */
    do {
      if (top == 0) return;
      --top;
      t_min = stack_min[top];
    } while (h->t_best <= t_min - fabs(t_min) * KD_EXIT_MARGIN);
    n = stack_node[top];
    t_max = stack_max[top];
  }
}

#define KD_PARAMS                                                                            \
  global const KdHeader *header, global const KdNode *nodes, global const int *refs,       \
      global const float *lanes, global const int *lane_prims, global const SphereBlock *spheres
#define KD_ARGS header, nodes, refs, lanes, lane_prims, spheres
RTCL_TRACE_KERNELS(kdtree, KD_PARAMS, KD_ARGS)
