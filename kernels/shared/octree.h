/* What the two octree kernels (kernels/accel/octree.cl, octree_ptr.cl)
 * share: the clip of a ray to the root box and the batched leaf tests.
 * OpenCL C only. */
#ifndef RTCL_SHARED_OCTREE_H
#define RTCL_SHARED_OCTREE_H

#include "shared/trace.h"

/* Clips one axis of the ray to the slab [lower, upper] (conservatively
 * widened, as the grid's: entering a cell too early costs a test, too late
 * a miss) and sets its step: the direction's sign, 0 when the ray does not
 * move along the axis (zero component, or a reciprocal that overflows);
 * such an axis limits nothing when the origin lies within the slab.
 * Returns 0 when the ray misses the slab. */
inline int octree_clip_axis(float o, float d, float inv, float lower, float upper, float* t0, float* t1,
                            int* step) {
  *step = (d == 0.0f || !rtcl_is_finite(inv)) ? 0 : (d > 0.0f ? 1 : -1);
  if (*step == 0) return o >= lower && o <= upper;
  float tn = ((*step > 0 ? lower : upper) - o) * inv;
  float tf = ((*step > 0 ? upper : lower) - o) * inv;
  *t0 = fmax(*t0, tn - fabs(tn) * RTCL_SLAB_WIDEN);
  *t1 = fmin(*t1, tf + fabs(tf) * RTCL_SLAB_WIDEN);
  return 1;
}

/* The references of one leaf, refs[begin .. end), gathered into batches of
 * eight per kind and tested when a batch is full (the indexed tests of
 * shared/triangle.h and shared/sphere.h: brute force's t, bit for bit).
 * Needs tri_batch, tri_count (and sphere_batch, sphere_count with spheres),
 * s, h, triangles, spheres in scope; returns from the traversal at the
 * first hit of an any-hit query. OCTREE_FINISH() tests what is pending and
 * returns. */
#define OCTREE_FLUSH_TRIANGLES()                                                        \
  if (tri_count > 0) {                                                                  \
    int found = intersect_triangle_refs(triangles, tri_batch, tri_count, s, h);         \
    tri_count = 0;                                                                      \
    if (found && RTCL_ANY_HIT) return;                                                  \
  }
#ifdef RTCL_HAS_SPHERES
#define OCTREE_FLUSH_SPHERES()                                                          \
  if (sphere_count > 0) {                                                               \
    int found = intersect_sphere_refs(spheres, sphere_batch, sphere_count, s, h);       \
    sphere_count = 0;                                                                   \
    if (found && RTCL_ANY_HIT) return;                                                  \
  }
#define OCTREE_BATCHES  \
  int tri_batch[8];     \
  int tri_count = 0;    \
  int sphere_batch[8];  \
  int sphere_count = 0;
#define OCTREE_GATHER_SPHERE(r)                  \
  if ((r) < 0) {                                 \
    sphere_batch[sphere_count++] = ~(r);         \
    if (sphere_count == 8) OCTREE_FLUSH_SPHERES() \
    continue;                                    \
  }
#else
#define OCTREE_FLUSH_SPHERES()
#define OCTREE_BATCHES \
  int tri_batch[8];    \
  int tri_count = 0;
#define OCTREE_GATHER_SPHERE(r)
#endif
#define OCTREE_FINISH()      \
  {                          \
    OCTREE_FLUSH_TRIANGLES() \
    OCTREE_FLUSH_SPHERES()   \
    return;                  \
  }
#define OCTREE_GATHER(begin, end)                 \
  for (uint k_ = (begin); k_ < (end); ++k_) {     \
    int r_ = refs[k_];                            \
    OCTREE_GATHER_SPHERE(r_)                      \
    tri_batch[tri_count++] = r_;                  \
    if (tri_count == 8) OCTREE_FLUSH_TRIANGLES()  \
  }

#endif
