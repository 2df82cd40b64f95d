/* Bounding volumes that cross the host/device boundary (src/rtcl/bounds/):
 * the one definition, compiled both as C++ (namespace rtcl, static_asserts in
 * src/rtcl/bounds/bounds_layouts.cpp) and as OpenCL C. Same rules as
 * layouts.h: 4-byte scalar fields, no float3. Include shared/layouts.h first.
 *
 * An AABB, an OBB and a k-DOP are all a SlabVolume: the intersection of
 * `count` slabs d_near[i] <= dot(normal[i], x) <= d_far[i] (Kay & Kajiya
 * 1986; the lecture's 包围体 section). The normals are the float values
 * stored here, so the set the record describes is exactly the set the ray
 * test tests; the builders round d_near down and d_far up, so that set
 * contains every point it was built from. */
#ifndef RTCL_SHARED_BOUNDS_LAYOUTS_H
#define RTCL_SHARED_BOUNDS_LAYOUTS_H

#ifndef __OPENCL_VERSION__
namespace rtcl {
#endif

/* The most directions of a k-DOP (the 13-direction set: 26 planes). */
#define RTCL_MAX_SLABS 13
/* Row length of d_near / d_far: RTCL_MAX_SLABS rounded up to a multiple of 4. */
#define RTCL_SLAB_ROW 16

/* 352 bytes. normal[i][3] is 0. Entries i >= count are unused (zero).
 * reach: an upper bound of |x| (Euclidean, world units) over the bounded
 * contents, which scales the ray test's rounding margin. count = 0 is the
 * empty volume, which no ray hits. */
typedef struct SlabVolume {
  float normal[RTCL_MAX_SLABS][4];
  float d_near[RTCL_SLAB_ROW];
  float d_far[RTCL_SLAB_ROW];
  float reach;
  rtcl_i32 count;
  rtcl_i32 pad[2];
} SlabVolume;

/* A bounding sphere: centre and radius (world units), reach as above.
 * 32 bytes. */
typedef struct SphereVolume {
  float cx, cy, cz, r;
  float reach;
  float pad[3];
} SphereVolume;

#ifndef __OPENCL_VERSION__
}  // namespace rtcl
#endif

#endif
