/* 8-wide BVH, one ray per work-item: the traversal of shared/bvh8_traverse.h
 * (eight child boxes of a node tested at once in float8 lanes, leaves of
 * eight primitives tested in float8 lanes) as the structure's trace kernels
 * (shared/trace.h), with the occluder cache for any hit. */
/* The leaves' triangle test inlined into the traversal (shared/triangle.h):
 * the lanes' arithmetic, 5-10% more rays/s than the call on the bunny, sponza
 * and sibenik, and the block's loads around it, 1-2% more (README,
 * "Results"). */
#define RTCL_INLINE_TRIANGLE_LANES
#define RTCL_INLINE_TRIANGLE_BLOCK
/* The ray setup inlined into the kernel (shared/ray.h): 0.97-1.14x the
 * kernel time on the twelve bench/ sets, above 1.03x on eleven (README,
 * "Kernel levers on the single-ray BVH"). */
#define RTCL_INLINE_RAY_SETUP
#include "shared/bvh8_traverse.h"

#define BVH_PARAMS                                                                                    \
  global const Bvh8Node *nodes, global const TriangleBlock *triangles, global const SphereBlock *spheres \
      BVH_FILTER_PARAMS
#define BVH_ARGS nodes, triangles, spheres BVH_FILTER_ARGS
inline int bvh_leaf(int leaf, const TraceRay* s, HitState* h, BVH_PARAMS) {
  return bvh_test_leaf(leaf, s, h, triangles, spheres);
}
RTCL_TRACE_KERNELS_OCCLUDER_CACHE(bvh, BVH_PARAMS, BVH_ARGS)
