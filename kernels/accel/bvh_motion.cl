/* 8-wide BVH over moving primitives (motion blur), one ray per work-item:
 * the traversal of accel/bvh.cl, with every primitive at the ray's time.
 * Each primitive has two keyframes, at shutter open (time 0) and close
 * (time 1), and at time tau lies at open + tau * (close - open), vertex by
 * vertex (a sphere: centre and radius), in float: the same arithmetic here
 * and in the shade kernel (render/shade.cl, RTCL_HAS_MOTION).
 *
 * Node bounds (src/rtcl/accel/bvh_motion.hpp):
 *  - swept (default): nodes[] hold each child's box over the whole shutter,
 *    the union of both keyframes' boxes;
 *  - RTCL_MOTION_LERP_NODES: nodes[] hold each child's box at open and
 *    nodes_close[] (same children) at close; the box tested is their
 *    interpolation at the ray's time, which contains the children at that
 *    time (each coordinate of a point moving linearly stays between the
 *    interpolated bounds).
 * Both are widened on the host to cover float rounding of the
 * interpolations.
 *
 * Ray times: ray i's time is times[i * time_stride + time_offset], a
 * fraction of the shutter interval, clamped to [0, 1] (NaN: 0). */
#include "shared/bvh8_stack.h"
#include "shared/trace.h"

#ifndef RTCL_STACK_SIZE
#define RTCL_STACK_SIZE 64
#endif

inline float8 motion_lerp8(float8 a, float8 b, float tau) { return a + tau * (b - a); }

#ifdef RTCL_MOTION_LERP_NODES
#define MOTION_NODE_PARAM , global const Bvh8Node *nodes_close
#define MOTION_NODE_ARG , nodes_close
#else
#define MOTION_NODE_PARAM
#define MOTION_NODE_ARG
#endif

__attribute__((noinline)) void bvh_motion_traverse(const TraceRay* s, HitState* h, float tau,
                                                   global const Bvh8Node* nodes MOTION_NODE_PARAM,
                                                   global const TriangleBlock* tri_open,
                                                   global const TriangleBlock* tri_close,
                                                   global const SphereBlock* sph_open,
                                                   global const SphereBlock* sph_close) {
  int stack_ref[RTCL_STACK_SIZE];
  float stack_t[RTCL_STACK_SIZE]; /* entry distance of stack_ref's box */
  int sp = 0;
  int ref = 0;
  for (;;) {
    if (ref >= 0) {
      global const float8* b = (global const float8*)nodes[ref].bounds;
#ifdef RTCL_MOTION_LERP_NODES
      global const float8* c = (global const float8*)nodes_close[ref].bounds;
#define MOTION_ROW(k) motion_lerp8(b[k], c[k], tau)
#else
#define MOTION_ROW(k) b[k]
#endif
      float8 t_entry, t_exit;
      rtcl_slabs8(MOTION_ROW(s->near_x), MOTION_ROW(s->near_y), MOTION_ROW(s->near_z), MOTION_ROW(s->far_x),
                  MOTION_ROW(s->far_y), MOTION_ROW(s->far_z), (float8)(s->ox), (float8)(s->oy), (float8)(s->oz),
                  (float8)(s->ix), (float8)(s->iy), (float8)(s->iz), (float8)(s->tmin), (float8)(h->t_best),
                  &t_entry, &t_exit);
#undef MOTION_ROW
      int8 hit = t_entry <= t_exit;
      if (rtcl_any8(hit)) {
        global const Bvh8Node* node = nodes + ref;
        RTCL_BVH8_PUSH_CHILDREN
      }
    } else {
      int leaf = ~ref;
#ifdef RTCL_HAS_SPHERES
      if (leaf & 1) {
        global const SphereBlock* a = sph_open + (leaf >> 1);
        global const SphereBlock* z = sph_close + (leaf >> 1);
        if (intersect_sphere_lanes(motion_lerp8(vload8(0, a->cx), vload8(0, z->cx), tau),
                                   motion_lerp8(vload8(0, a->cy), vload8(0, z->cy), tau),
                                   motion_lerp8(vload8(0, a->cz), vload8(0, z->cz), tau),
                                   motion_lerp8(vload8(0, a->r), vload8(0, z->r), tau), vload8(0, a->prim), s, h) &&
            RTCL_ANY_HIT)
          return;
      } else
#endif
      {
        global const float* a = &tri_open[leaf >> 1].v[0][0][0];
        global const float* z = &tri_close[leaf >> 1].v[0][0][0];
#define MOTION_VERTEX(ROW) motion_lerp8(vload8(ROW, a), vload8(ROW, z), tau)
        if (intersect_triangle_lanes(MOTION_VERTEX(s->kx), MOTION_VERTEX(s->ky), MOTION_VERTEX(s->kz),
                                     MOTION_VERTEX(3 + s->kx), MOTION_VERTEX(3 + s->ky), MOTION_VERTEX(3 + s->kz),
                                     MOTION_VERTEX(6 + s->kx), MOTION_VERTEX(6 + s->ky), MOTION_VERTEX(6 + s->kz),
                                     vload8(0, tri_open[leaf >> 1].prim), s, h) &&
            RTCL_ANY_HIT)
          return;
#undef MOTION_VERTEX
      }
    }
    do {
      if (sp == 0) return;
      --sp;
    } while (!RTCL_ANY_HIT && stack_t[sp] > h->t_best);
    ref = stack_ref[sp];
  }
}

kernel void RTCL_TRACE_KERNEL_NAME(bvh_motion)(global const Ray* rays, global Hit* hits, uint ray_count,
                                               global const float* times, uint time_stride, uint time_offset,
                                               global const Bvh8Node* nodes MOTION_NODE_PARAM,
                                               global const TriangleBlock* tri_open,
                                               global const TriangleBlock* tri_close,
                                               global const SphereBlock* sph_open,
                                               global const SphereBlock* sph_close) {
  uint i = get_global_id(0);
  if (i >= ray_count) return;
  float tau = times[i * time_stride + time_offset];
  tau = rtcl_is_nan(tau) ? 0.0f : fmin(fmax(tau, 0.0f), 1.0f); /* a bit test: fast math assumes no NaN */
  TraceRay s;
  HitState h;
  if (begin_trace(rays, i, &s, &h))
    bvh_motion_traverse(&s, &h, tau, nodes MOTION_NODE_ARG, tri_open, tri_close, sph_open, sph_close);
  end_trace(hits, i, &h);
}
