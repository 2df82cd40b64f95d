/* The public records of queries (docs/api.md), shared by host and kernels:
 * compiled both as C++ (namespace rtcl, static_asserts in
 * src/rtcl/layouts.cpp) and as OpenCL C. Every field is a 4-byte scalar so
 * that no compiler inserts padding. Installed as <rtcl/shared/query_layouts.h>;
 * kernels/shared/layouts.h adds the structures' internal records. */
#ifndef RTCL_SHARED_QUERY_LAYOUTS_H
#define RTCL_SHARED_QUERY_LAYOUTS_H

#ifdef __OPENCL_VERSION__
typedef int rtcl_i32;
typedef uint rtcl_u32;
#else
#include <cstdint>
namespace rtcl {
typedef std::int32_t rtcl_i32;
typedef std::uint32_t rtcl_u32;
#endif

/* A ray: 32 bytes, 4-byte aligned, identical to one record of the ray file.
 * Valid hits have tmin <= t <= tmax. The direction need not be unit length;
 * t is measured in units of |dir|. */
typedef struct Ray {
  float ox, oy, oz;
  float dx, dy, dz;
  float tmin, tmax;
} Ray;

/* A query result: 16 bytes, 4-byte aligned, identical to one hit-file record.
 * Miss: t = +inf, prim = -1, u = v = 0. For a triangle (v0, v1, v2) the hit
 * point is (1-u-v)*v0 + u*v1 + v*v2; for a sphere u = v = 0.
 * prim: triangle ids come first (0 .. triangle_count-1), then spheres. */
typedef struct Hit {
  float t, u, v;
  rtcl_i32 prim;
} Hit;

/* A closest-point answer: 32 bytes, 4-byte aligned. (x, y, z) is the
 * nearest point of primitive prim to the query point and distance its
 * Euclidean distance (float, scene units). For a triangle (v0, v1, v2) the
 * point is (1-u-v)*v0 + u*v1 + v*v2; for a sphere u = v = 0. None within the
 * query's radius: distance = +inf, prim = -1, x = y = z = NaN, u = v = 0. */
typedef struct PointHit {
  float x, y, z;
  float distance;
  float u, v;
  rtcl_i32 prim;
  rtcl_u32 reserved; /* 0 */
} PointHit;

#ifndef __OPENCL_VERSION__
} /* namespace rtcl */
#endif
#endif
