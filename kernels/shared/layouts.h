/* Records that cross the host/device boundary: the one definition, compiled
 * both as C++ (namespace rtcl, with static_asserts in src/rtcl/layouts.cpp)
 * and as OpenCL C. Every field is a 4-byte scalar so that no compiler inserts
 * padding; a record's size is a multiple of its device alignment. */
#ifndef RTCL_SHARED_LAYOUTS_H
#define RTCL_SHARED_LAYOUTS_H

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

/* Leaves hold up to RTCL_BLOCK_WIDTH primitives in SoA form, so that one
 * work-item tests all of them with float8 arithmetic. */
#define RTCL_BLOCK_WIDTH 8

/* Eight triangles, SoA: v[vertex][axis][lane]. Unused lanes have NaN vertices
 * (every comparison fails, so they never hit) and prim = -1. 320 bytes. */
typedef struct TriangleBlock {
  float v[3][3][RTCL_BLOCK_WIDTH];
  rtcl_i32 prim[RTCL_BLOCK_WIDTH];
} TriangleBlock;

/* Eight spheres, SoA: centre x, y, z and radius. Unused lanes have radius NaN
 * and prim = -1. 160 bytes. */
typedef struct SphereBlock {
  float cx[RTCL_BLOCK_WIDTH], cy[RTCL_BLOCK_WIDTH], cz[RTCL_BLOCK_WIDTH];
  float r[RTCL_BLOCK_WIDTH];
  rtcl_i32 prim[RTCL_BLOCK_WIDTH];
} SphereBlock;

/* An 8-wide BVH node, SoA child bounds: bounds[0..2] = lower x, y, z,
 * bounds[3..5] = upper x, y, z, each for the 8 children. An empty slot has
 * lower = +inf, upper = -inf and child = RTCL_CHILD_EMPTY. 224 bytes, so
 * every node in an array starts on a 32-byte (float8) boundary. */
typedef struct Bvh8Node {
  float bounds[6][RTCL_BLOCK_WIDTH];
  rtcl_i32 child[RTCL_BLOCK_WIDTH];
} Bvh8Node;

/* Child references: >= 0 is an inner node index; RTCL_CHILD_EMPTY is an empty
 * slot; any other negative c is a leaf with ref = ~c (>= 0): ref >> 1 indexes
 * a TriangleBlock when (ref & 1) == 0, else a SphereBlock. */
#define RTCL_CHILD_EMPTY ((rtcl_i32)0x80000000)
#define RTCL_LEAF_TRIANGLES(block) (~((rtcl_i32)(block) << 1))
#define RTCL_LEAF_SPHERES(block) (~(((rtcl_i32)(block) << 1) | 1))

/* A uniform grid (kernels/accel/grid.cl): res[0] x res[1] x res[2] cells
 * over the box [lower, lower + res * cell]. Cell (i, j, k) is the closed box
 * from lower + (i, j, k) * cell to lower + (i + 1, j + 1, k + 1) * cell, each
 * coordinate computed in float as lower[a] + (float)n * cell[a] by host and
 * kernel alike; its index is i + res[0] * (j + res[1] * k). Its references
 * are refs[cell_begin[c] .. cell_begin[c + 1]) (compact grid, Lagae & Dutre
 * 2008): triangles first, as r >= 0 (lane r & 7 of triangle block r >> 3,
 * id-ordered blocks), then spheres, as ~r < 0 (sphere block array). 48 bytes;
 * element [3] of each row is unused. */
typedef struct GridHeader {
  float lower[4];
  float cell[4];  /* cell size per axis, > 0 */
  rtcl_i32 res[4]; /* cells per axis, >= 1 */
} GridHeader;

/* A BSP / kd-tree node (kernels/accel/kdtree.cl; built by
 * src/rtcl/accel/bsp.cpp and kdtree.cpp): 8 bytes, in depth-first order.
 * flags bits 0..1: the split axis 0, 1, 2 (x, y, z) of an inner node, or
 * RTCL_KD_LEAF. Inner node n: its child below the plane (coordinate <=
 * split) is node n + 1, its child above (>= split) is node flags >> 2, and
 * data holds the split coordinate's float bits. Leaf: its references are
 * refs[(flags >> 2) .. (flags >> 2) + data), triangles first as r >= 0 (lane
 * r & 7 of triangle block r >> 3, id-ordered blocks), then spheres as ~r < 0,
 * each kind in ascending order. Every index is < 2^30. */
typedef struct KdNode {
  rtcl_u32 flags;
  rtcl_u32 data;
} KdNode;
#define RTCL_KD_LEAF 3u
#define RTCL_KD_INNER(axis, above) ((rtcl_u32)(axis) | ((rtcl_u32)(above) << 2))
#define RTCL_KD_LEAF_NODE(first) (RTCL_KD_LEAF | ((rtcl_u32)(first) << 2))

/* The tree's root box [lower, upper] (closed, float), which contains every
 * stored primitive; traversal clips the ray to it. 32 bytes; element [3] of
 * each row is unused. */
typedef struct KdHeader {
  float lower[4];
  float upper[4];
} KdHeader;

#ifndef __OPENCL_VERSION__
} /* namespace rtcl */
#endif
#endif
