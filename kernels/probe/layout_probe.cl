/* The device compiler's view of the shared records (kernels/shared/layouts.h),
 * for tests/layout_probe_test.cpp, which compares it with the host's.
 * probe_layout writes sizes, array strides and field offsets in bytes;
 * probe_fields reads host-written records field by field and writes one
 * Hit field by field, proving that both sides address the same bytes. */
#include "shared/layouts.h"

/* Byte offset of a field inside the record `rec` points to. OpenCL C 1.2 has
 * no offsetof; the difference of two pointers into one object is portable. */
#define PROBE_OFFSET(rec, field) \
  ((uint)((global const char*)&(rec)->field - (global const char*)(rec)))
#define PROBE_STRIDE(rec) ((uint)((global const char*)((rec) + 1) - (global const char*)(rec)))

/* out[0] = number of entries that follow; then, in this order (the host test
 * lists the same entries in the same order): */
kernel void probe_layout(global const Ray* ray, global const Hit* hit, global const TriangleBlock* tri,
                         global const SphereBlock* sph, global const Bvh8Node* node, global uint* out) {
  uint k = 1;
  out[k++] = sizeof(Ray);
  out[k++] = PROBE_STRIDE(ray);
  out[k++] = PROBE_OFFSET(ray, ox);
  out[k++] = PROBE_OFFSET(ray, oy);
  out[k++] = PROBE_OFFSET(ray, oz);
  out[k++] = PROBE_OFFSET(ray, dx);
  out[k++] = PROBE_OFFSET(ray, dy);
  out[k++] = PROBE_OFFSET(ray, dz);
  out[k++] = PROBE_OFFSET(ray, tmin);
  out[k++] = PROBE_OFFSET(ray, tmax);
  out[k++] = sizeof(Hit);
  out[k++] = PROBE_STRIDE(hit);
  out[k++] = PROBE_OFFSET(hit, t);
  out[k++] = PROBE_OFFSET(hit, u);
  out[k++] = PROBE_OFFSET(hit, v);
  out[k++] = PROBE_OFFSET(hit, prim);
  out[k++] = sizeof(TriangleBlock);
  out[k++] = PROBE_STRIDE(tri);
  out[k++] = PROBE_OFFSET(tri, v);
  out[k++] = PROBE_OFFSET(tri, v[1][0][0]);
  out[k++] = PROBE_OFFSET(tri, v[0][1][0]);
  out[k++] = PROBE_OFFSET(tri, v[2][2][7]);
  out[k++] = PROBE_OFFSET(tri, prim);
  out[k++] = sizeof(SphereBlock);
  out[k++] = PROBE_STRIDE(sph);
  out[k++] = PROBE_OFFSET(sph, cx);
  out[k++] = PROBE_OFFSET(sph, cy);
  out[k++] = PROBE_OFFSET(sph, cz);
  out[k++] = PROBE_OFFSET(sph, r);
  out[k++] = PROBE_OFFSET(sph, prim);
  out[k++] = sizeof(Bvh8Node);
  out[k++] = PROBE_STRIDE(node);
  out[k++] = PROBE_OFFSET(node, bounds);
  out[k++] = PROBE_OFFSET(node, bounds[3][0]);
  out[k++] = PROBE_OFFSET(node, bounds[5][7]);
  out[k++] = PROBE_OFFSET(node, child);
  out[k++] = RTCL_BLOCK_WIDTH;
  out[k++] = (uint)RTCL_CHILD_EMPTY;
  out[k++] = (uint)RTCL_LEAF_TRIANGLES(5);
  out[k++] = (uint)RTCL_LEAF_SPHERES(5);
  out[0] = k - 1;
}

/* Copies every field of the records, in declaration order, into floats and
 * ints; writes hit[0] = {t = 1.5, u = 0.25, v = 0.125, prim = -7}. */
kernel void probe_fields(global const Ray* ray, global const TriangleBlock* tri, global const SphereBlock* sph,
                         global const Bvh8Node* node, global float* floats, global int* ints, global Hit* hit) {
  uint f = 0, n = 0;
  floats[f++] = ray->ox;
  floats[f++] = ray->oy;
  floats[f++] = ray->oz;
  floats[f++] = ray->dx;
  floats[f++] = ray->dy;
  floats[f++] = ray->dz;
  floats[f++] = ray->tmin;
  floats[f++] = ray->tmax;
  for (int vertex = 0; vertex < 3; ++vertex)
    for (int axis = 0; axis < 3; ++axis)
      for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) floats[f++] = tri->v[vertex][axis][lane];
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) ints[n++] = tri->prim[lane];
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) floats[f++] = sph->cx[lane];
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) floats[f++] = sph->cy[lane];
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) floats[f++] = sph->cz[lane];
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) floats[f++] = sph->r[lane];
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) ints[n++] = sph->prim[lane];
  for (int row = 0; row < 6; ++row)
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) floats[f++] = node->bounds[row][lane];
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) ints[n++] = node->child[lane];
  Hit h;
  h.t = 1.5f;
  h.u = 0.25f;
  h.v = 0.125f;
  h.prim = -7;
  hit[0] = h;
  /* the second record is written field by field, through the array */
  hit[1].t = 2.5f;
  hit[1].u = 0.5f;
  hit[1].v = 0.375f;
  hit[1].prim = 123456;
}
