/* Micro-benchmark of the per-node tests of the mixed-volume BVH
 * (bench/volume_cost_bench.cpp): each work-item sets up one ray and runs one
 * test kind over `count` consecutive records, counting the records it
 * reports hit (written out, so no test is optimised away). Closest-hit
 * setup (RTCL_ANY_HIT 0). The k-DOP and OBB filters get [tmin, tmax] as
 * the box interval of every lane. */
#include "shared/trace.h"
#include "shared/sphere_filter8.h"
#include "shared/kdop_filter8.h"
#include "shared/obb_filter8.h"

kernel void cost_boxes8(global const Ray* rays, global const Bvh8Node* nodes, uint count, global int* out) {
  uint i = get_global_id(0);
  TraceRay s;
  HitState h;
  int acc = 0;
  if (begin_trace(rays, i, &s, &h))
    for (uint k = 0; k < count; ++k) {
      float8 t;
      acc += rtcl_any8(intersect_boxes8(nodes + k, &s, h.t_best, &t));
    }
  out[i] = acc;
}

kernel void cost_spheres8(global const Ray* rays, global const Bvh8Spheres* records, uint count, global int* out) {
  uint i = get_global_id(0);
  TraceRay s;
  HitState h;
  int acc = 0;
  if (begin_trace(rays, i, &s, &h)) {
    SphereFilterRay f;
    sphere_filter_setup(&s, &f);
    for (uint k = 0; k < count; ++k) acc += rtcl_any8(sphere_filter8(records + k, &s, &f));
  }
  out[i] = acc;
}

kernel void cost_triangles8(global const Ray* rays, global const TriangleBlock* blocks, uint count, global int* out) {
  uint i = get_global_id(0);
  TraceRay s;
  HitState h;
  int acc = 0;
  if (begin_trace(rays, i, &s, &h))
    for (uint k = 0; k < count; ++k) acc += intersect_triangles8(blocks + k, &s, &h);
  out[i] = acc;
}

kernel void cost_kdop8(global const Ray* rays, global const Bvh8Kdop* records, uint count, global int* out) {
  uint i = get_global_id(0);
  TraceRay s;
  HitState h;
  int acc = 0;
  if (begin_trace(rays, i, &s, &h)) {
    KdopFilterRay f;
    kdop_filter_setup(&s, &f);
    float8 tn = (float8)(s.tmin), tf = (float8)(h.t_best);
    for (uint k = 0; k < count; ++k) acc += rtcl_any8(kdop_filter8(records + k, &f, tn, tf));
  }
  out[i] = acc;
}

kernel void cost_obb8(global const Ray* rays, global const Bvh8Obb* records, uint count, global int* out) {
  uint i = get_global_id(0);
  TraceRay s;
  HitState h;
  int acc = 0;
  if (begin_trace(rays, i, &s, &h)) {
    float e = obb_filter_setup(&s);
    float8 tn = (float8)(s.tmin), tf = (float8)(h.t_best);
    for (uint k = 0; k < count; ++k) acc += rtcl_any8(obb_filter8(records + k, &s, e, tn, tf));
  }
  out[i] = acc;
}
