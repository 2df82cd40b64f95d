/* What every single-ray trace kernel does around its traversal: read the
 * ray, set it up, write the hit; and the primitive and box tests it uses.
 * OpenCL C only. */
#ifndef RTCL_SHARED_TRACE_H
#define RTCL_SHARED_TRACE_H

#include "shared/box.h"
#include "shared/sphere.h"
#include "shared/triangle.h"

/* Returns 0 (and leaves a miss in h) for a ray that cannot be traced. */
inline int begin_trace(global const Ray* rays, uint i, TraceRay* s, HitState* h) {
  Ray r = rays[i];
  hit_state_init(h, r.tmax);
  return trace_ray_setup(r, s);
}

inline void end_trace(global Hit* hits, uint i, const HitState* h) {
  Hit out;
  out.t = hit_state_t(h);
  out.u = h->u;
  out.v = h->v;
  out.prim = h->prim;
  hits[i] = out;
}

/* The kernel of this program's query: trace_closest_NAME when built with
 * RTCL_QUERY_CLOSEST, trace_any_NAME with RTCL_QUERY_ANY. */
#ifdef RTCL_QUERY_ANY
#define RTCL_TRACE_KERNEL_NAME(NAME) trace_any_##NAME
#else
#define RTCL_TRACE_KERNEL_NAME(NAME) trace_closest_##NAME
#endif

/* With RTCL_TRACE_ORDER (a Coherence::scattered call, kernels/accel/ray_sort.cl)
 * the kernel takes `global const uint* order` after ray_count: the k-th ray
 * traced is rays[order[k]], and its hit goes to hits[order[k]]. The ray
 * RTCL_TRACE_PREFETCH places ahead in the order is prefetched: the rays
 * are read out of memory order, and without the prefetch the sort keeps
 * less of its gain. */
#ifdef RTCL_TRACE_ORDER
#define RTCL_TRACE_ORDER_PARAM global const uint *order,
#define RTCL_TRACE_HIT_INDEX(k) order[k]
#define RTCL_TRACE_PREFETCH 8
#define RTCL_TRACE_RAY_INDEX(k) rtcl_trace_ray_index(rays, order, k, ray_count)
inline uint rtcl_trace_ray_index(global const Ray* rays, global const uint* order, uint k, uint ray_count) {
  uint ahead = k + RTCL_TRACE_PREFETCH;
#ifdef __clang__
  if (ahead < ray_count) __builtin_prefetch(rays + order[ahead]);
#else
  if (ahead < ray_count) prefetch((global const float8*)(rays + order[ahead]), 1);
#endif
  return order[k];
}
#else
#define RTCL_TRACE_ORDER_PARAM
#define RTCL_TRACE_HIT_INDEX(k) (k)
#define RTCL_TRACE_RAY_INDEX(k) (k)
#endif

/* Defines the kernel from an inline function
 * NAME_traverse(const TraceRay*, HitState*, STRUCTURE_PARAMS...), which
 * ends at its first hit when RTCL_ANY_HIT is 1. */
#define RTCL_TRACE_KERNELS(NAME, PARAMS, ARGS)                                                      \
  kernel void RTCL_TRACE_KERNEL_NAME(NAME)(global const Ray* rays, global Hit* hits, uint ray_count, \
                                           RTCL_TRACE_ORDER_PARAM PARAMS) {                          \
    uint i = get_global_id(0);                                                                      \
    if (i >= ray_count) return;                                                                     \
    TraceRay s;                                                                                     \
    HitState h;                                                                                     \
    if (begin_trace(rays, RTCL_TRACE_RAY_INDEX(i), &s, &h)) NAME##_traverse(&s, &h, ARGS);          \
    end_trace(hits, RTCL_TRACE_HIT_INDEX(i), &h);                                                   \
  }

/* RTCL_TRACE_KERNELS for a structure whose any-hit traversal reports the
 * leaf that blocked the ray: NAME_traverse returns that leaf's code (-1
 * when the ray is not blocked, and always at closest hit), and
 * NAME_leaf(code, s, h, ARGS) tests one leaf. Its any-hit kernel traces a
 * run of ceil(ray_count / global size) consecutive rays per work-item and
 * tests each ray first against the leaf that blocked the previous ray of
 * the run (a shadow cache, after Haines & Greenberg 1986, "The light
 * buffer"): rays that share an occluder skip the traversal. Any leaf that
 * blocks the ray within [tmin, tmax] answers an any-hit query, so hit or
 * miss is the traversal's; the reported occluder may differ. The host
 * chooses the run by the launch's size (Accel::TraceKernels::occluder_run):
 * one work-item per ray is a run of 1. Its closest-hit kernel is
 * RTCL_TRACE_KERNELS's. */
#ifdef RTCL_QUERY_ANY
#define RTCL_TRACE_KERNELS_OCCLUDER_CACHE(NAME, PARAMS, ARGS)                                        \
  kernel void trace_any_##NAME(global const Ray* rays, global Hit* hits, uint ray_count,              \
                               RTCL_TRACE_ORDER_PARAM PARAMS) {                                      \
    ulong run = ((ulong)ray_count + get_global_size(0) - 1) / get_global_size(0);                    \
    ulong first = get_global_id(0) * run;                                                             \
    if (first >= ray_count) return;                                                                   \
    uint end = (uint)min(first + run, (ulong)ray_count);                                              \
    int occluder = -1;                                                                                \
    for (uint i = (uint)first; i < end; ++i) {                                                        \
      TraceRay s;                                                                                     \
      HitState h;                                                                                     \
      if (begin_trace(rays, RTCL_TRACE_RAY_INDEX(i), &s, &h) &&                                      \
          (occluder < 0 || !NAME##_leaf(occluder, &s, &h, ARGS)))                                     \
        occluder = NAME##_traverse(&s, &h, ARGS);                                                     \
      end_trace(hits, RTCL_TRACE_HIT_INDEX(i), &h);                                                   \
    }                                                                                                 \
  }
#else
#define RTCL_TRACE_KERNELS_OCCLUDER_CACHE RTCL_TRACE_KERNELS
#endif

#endif
