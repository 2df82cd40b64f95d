/* The device compiler's view of the shared records (kernels/shared/layouts.h,
 * kernels/shared/render_layouts.h), for tests/layout_probe_test.cpp, which
 * compares it with the host's. probe_layout writes, for every entry of
 * probe/layout_entries.h in order, the size, stride, offset or value;
 * probe_fields reads host-written records field by field and writes one
 * Hit field by field, proving that both sides address the same bytes. */
#include "shared/layouts.h"
#include "shared/render_layouts.h"
#include "shared/sampling.h"
#include "shared/bounds_layouts.h"
#include "shared/beam_layouts.h"

/* Byte offsets inside a private record: layout does not depend on the
 * address space, and OpenCL C 1.2 has no offsetof; the difference of two
 * pointers into one object is portable. */
#define RTCL_PROBE_RECORD(T)             \
  {                                      \
    T pair[2];                           \
    out[k++] = (uint)sizeof(T);          \
    out[k++] = (uint)((private char*)&pair[1] - (private char*)&pair[0]); \
  }
#define RTCL_PROBE_FIELD(T, member) \
  {                                 \
    T record;                       \
    out[k++] = (uint)((private char*)&record.member - (private char*)&record); \
  }
#define RTCL_PROBE_SIZE(NAME, TYPE) out[k++] = (uint)sizeof(TYPE);
#define RTCL_PROBE_VALUE(EXPR) out[k++] = (uint)(EXPR);

/* out[0] = number of entries that follow. */
kernel void probe_layout(global uint* out) {
  uint k = 1;
#include "probe/layout_entries.h"
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
