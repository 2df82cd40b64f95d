/* What every trace kernel does around its traversal: read the ray, set it up,
 * write the hit. OpenCL C only. */
#ifndef RTCL_SHARED_TRACE_H
#define RTCL_SHARED_TRACE_H

#include "shared/intersect.h"

/* Returns 0 (and leaves a miss in h) for a ray that cannot be traced. */
inline int begin_trace(global const Ray* rays, uint i, TraceRay* s, HitState* h) {
  Ray r = rays[i];
  h->t_best = nextafter(r.tmax, INFINITY);
  h->u = 0.0f;
  h->v = 0.0f;
  h->prim = -1;
  return trace_ray_setup(r, s);
}

inline void end_trace(global Hit* hits, uint i, const HitState* h) {
  Hit out;
  out.t = h->prim < 0 ? INFINITY : h->t_best;
  out.u = h->u;
  out.v = h->v;
  out.prim = h->prim;
  hits[i] = out;
}

/* Defines trace_closest_NAME and trace_any_NAME from an inline function
 * NAME_traverse(const TraceRay*, HitState*, STRUCTURE_PARAMS..., int any_hit)
 * which this macro calls with the kernels' structure arguments. */
#define RTCL_TRACE_KERNELS(NAME, PARAMS, ARGS)                                                \
  kernel void trace_closest_##NAME(global const Ray* rays, global Hit* hits, uint ray_count,  \
                                   PARAMS) {                                                  \
    uint i = get_global_id(0);                                                                \
    if (i >= ray_count) return;                                                               \
    TraceRay s;                                                                               \
    HitState h;                                                                               \
    if (begin_trace(rays, i, &s, &h)) NAME##_traverse(&s, &h, ARGS, 0);                       \
    end_trace(hits, i, &h);                                                                   \
  }                                                                                           \
  kernel void trace_any_##NAME(global const Ray* rays, global Hit* hits, uint ray_count,      \
                               PARAMS) {                                                      \
    uint i = get_global_id(0);                                                                \
    if (i >= ray_count) return;                                                               \
    TraceRay s;                                                                               \
    HitState h;                                                                               \
    if (begin_trace(rays, i, &s, &h)) NAME##_traverse(&s, &h, ARGS, 1);                       \
    end_trace(hits, i, &h);                                                                   \
  }

#endif
