/* Brute force: every ray against every primitive block. The reference
 * structure on the device; O(rays x primitives). */
#include "shared/trace.h"

inline void brute_traverse(const TraceRay* s, HitState* h, global const TriangleBlock* triangles,
                           uint triangle_block_count, global const SphereBlock* spheres,
                           uint sphere_block_count) {
  for (uint b = 0; b < triangle_block_count; ++b)
    if (intersect_triangles8(triangles + b, s, h) && RTCL_ANY_HIT) return;
#ifdef RTCL_HAS_SPHERES
  for (uint b = 0; b < sphere_block_count; ++b)
    if (intersect_spheres8(spheres + b, s, h) && RTCL_ANY_HIT) return;
#endif
}

#define BRUTE_PARAMS                                                                   \
  global const TriangleBlock *triangles, uint triangle_block_count,                    \
      global const SphereBlock *spheres, uint sphere_block_count
#define BRUTE_ARGS triangles, triangle_block_count, spheres, sphere_block_count
RTCL_TRACE_KERNELS(brute, BRUTE_PARAMS, BRUTE_ARGS)
