/* Records that cross the host/device boundary: the one definition, compiled
 * both as C++ (namespace rtcl, with static_asserts in src/rtcl/layouts.cpp)
 * and as OpenCL C. Every field is a 4-byte scalar so that no compiler inserts
 * padding; a record's size is a multiple of its device alignment. */
#ifndef RTCL_SHARED_LAYOUTS_H
#define RTCL_SHARED_LAYOUTS_H

#ifdef __OPENCL_VERSION__
#include "shared/query_layouts.h"
#else
#include <rtcl/shared/query_layouts.h>
namespace rtcl {
#endif

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

/* Bounding-sphere filters of the eight children of one node of the
 * mixed-volume BVH (src/rtcl/accel/bvh_volumes.hpp, kernels/accel/bvh.cl
 * with RTCL_BVH_SPHERES): centre x, y, z and a radius already widened by
 * the ray-independent part of the rounding margin (kernels/shared/
 * sphere_filter8.h); r < 0 marks a lane without a sphere (its box alone
 * decides). 128 bytes, so every record starts on a float8 boundary. */
typedef struct Bvh8Spheres {
  float cx[RTCL_BLOCK_WIDTH], cy[RTCL_BLOCK_WIDTH], cz[RTCL_BLOCK_WIDTH];
  float r[RTCL_BLOCK_WIDTH];
} Bvh8Spheres;

/* k-DOP filters of the eight children of one node of the mixed-volume BVH
 * (kernels/shared/kdop_filter8.h): with the node's boxes (the three axis
 * slabs) they form each child's 14-DOP, the 7-direction set of
 * src/rtcl/bounds/kdop.hpp. Row j (0..3) is slab j, d_near[j][lane] <=
 * dot(n_j, x) <= d_far[j][lane], for the body diagonals
 * n_j = RTCL_KDOP_DIAGONAL * (1, 1, 1), (1, 1, -1), (1, -1, 1), (-1, 1, 1)
 * (the float unit vectors of kdop.cpp, in that order); d_near and d_far are
 * already widened outward by the ray-independent part of the rounding
 * margin. A lane without a filter has d_near = -FLT_MAX, d_far = FLT_MAX.
 * 256 bytes: every record starts on a float8 boundary. */
#define RTCL_KDOP_FILTER_SLABS 4
#define RTCL_KDOP_DIAGONAL 0.577350269189625764509148780502f
typedef struct Bvh8Kdop {
  float d_near[RTCL_KDOP_FILTER_SLABS][RTCL_BLOCK_WIDTH];
  float d_far[RTCL_KDOP_FILTER_SLABS][RTCL_BLOCK_WIDTH];
} Bvh8Kdop;

/* Oriented-box filters of the eight children of one node of the
 * mixed-volume BVH (kernels/shared/obb_filter8.h): child lane's OBB is
 * d_near[i][lane] <= dot(u_i, x) <= d_far[i][lane], i = 0..2, with the unit
 * axis u_i = (axis[3i][lane], axis[3i + 1][lane], axis[3i + 2][lane]) (float
 * values, orthonormal to ~1e-7; the stored slabs contain the child's
 * contents exactly for these float axes) and d_near, d_far widened outward
 * by the ray-independent part of the rounding margin. A lane without a
 * filter has the world axes and d_near = -FLT_MAX, d_far = FLT_MAX.
 * 480 bytes (15 float8 rows). */
typedef struct Bvh8Obb {
  float axis[9][RTCL_BLOCK_WIDTH];
  float d_near[3][RTCL_BLOCK_WIDTH];
  float d_far[3][RTCL_BLOCK_WIDTH];
} Bvh8Obb;

/* A node's filter in the mixed-volume BVH (filter_of[node] in
 * kernels/accel/bvh.cl): -1 for none, else (record index << 2) | kind, the
 * record indexing the array of that kind. */
#define RTCL_FILTER_NONE (-1)
#define RTCL_FILTER_SPHERE 0
#define RTCL_FILTER_KDOP 1
#define RTCL_FILTER_OBB 2
#define RTCL_FILTER_REF(kind, index) ((rtcl_i32)(((index) << 2) | (kind)))
#define RTCL_FILTER_KIND(ref) ((ref) & 3)
#define RTCL_FILTER_INDEX(ref) ((ref) >> 2)

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
 * id-ordered blocks), then spheres, as ~r < 0 (sphere block array).
 * Macrocells (empty-space skipping): cells are grouped into cubes of
 * 2^macro[3] cells per side, macrocell (I, J, K) holding the cells (i, j, k)
 * with i >> macro[3] == I (and so on; the last ones per axis may be
 * partial), index I + macro[0] * (J + macro[1] * K); occupied[m] is 1 when
 * one of its cells has a reference, else 0. Reference lanes (so that a
 * cell's triangles load as contiguous float8 runs, no gather): row
 * 3 * vertex + axis of a float array with rows lane_stride apart holds, at
 * position k, that coordinate of the triangle of reference k (NaN where
 * reference k is a sphere, and in the 8 positions past the last
 * reference), and lane_prims[k] its primitive id (-1 there). Occupied
 * space: occupied_bounds (Bvh8Node bounds layout) holds, for each octant of
 * the grid split at cell res / 2 on every axis, the box of its cells that
 * have references, on cell planes (empty slot: lower +inf, upper -inf);
 * every primitive lies in their union. A second array, occupied_boxes,
 * holds 8 such row sets: set o the boxes of octant o's own octants (split
 * at the middle cell of its range per axis), whose union is octant o's
 * box's occupied part. 272 bytes; element [3] of lower,
 * cell and res is unused. */
typedef struct GridHeader {
  float occupied_bounds[6][RTCL_BLOCK_WIDTH]; /* first: float8 rows, 32-byte aligned */
  float lower[4];
  float cell[4];     /* cell size per axis, > 0 */
  rtcl_i32 res[4];   /* cells per axis, >= 1 */
  rtcl_i32 macro[4]; /* macrocells per axis, >= 1; [3]: log2 of a macrocell's side in cells */
  rtcl_i32 lane_stride; /* references + 8 */
  rtcl_i32 unused[3];
} GridHeader;

/* An octree addressed by node codes (kernels/accel/octree.cl; lecture,
 * 空间八叉树剖分技术): a cube split at its centre down to at most `depth`
 * (N <= 16) levels, over the integer lattice 0 .. 2^N per axis. Lattice
 * plane n on axis a lies at lower[a] + (float)n * cell, computed so by host
 * and kernel alike. The code of a node at level i is the digits q1 .. qi
 * followed by N - i digits F, one hexadecimal digit each, q1 the highest of
 * the low 4N bits of a 64-bit word; child q of a node holds the points whose
 * lattice coordinate bits at its level give q = i + 2j + 4k (property 1).
 * The leaves that hold primitives are a table sorted by code: codes[0 ..
 * leaf_count) (ulong); leaf l holds its own triangle blocks [leaf_begin[2l],
 * leaf_begin[2l + 2]) and sphere blocks [leaf_begin[2l + 1], leaf_begin[2l +
 * 3]), ids ascending (copies: a primitive in several leaves is in a block of
 * each). Leaves without primitives are not stored. bucket_begin[b], for the b-th
 * prefix of top_digits digits (base 8, b in [0, 8^top_digits)), is the first
 * leaf whose code is not below that prefix followed by digits 0;
 * bucket_begin[8^top_digits] = leaf_count (top_digits 0: one bucket, the
 * whole table). 32 bytes. */
typedef struct OctreeHeader {
  float lower[4];        /* [3] unused */
  float cell;            /* lattice unit, > 0, the same on every axis (a cube) */
  rtcl_i32 depth;        /* N, 0 .. RTCL_OCTREE_MAX_DEPTH */
  rtcl_u32 leaf_count;
  rtcl_i32 top_digits;   /* digits indexing bucket_begin, 0 .. min(N, 7) */
} OctreeHeader;

/* The deepest code octree a 64-bit code holds: 16 digits of 4 bits. */
#define RTCL_OCTREE_MAX_DEPTH 16

/* A node of a pointer octree (kernels/accel/octree_ptr.cl; octree-ptr and
 * octree-r): three split planes and eight children, child q covering the
 * upper side of split[0] when q & 1, of split[1] when q & 2, of split[2]
 * when q & 4 (closed boxes). child[q] >= 0 is an inner node index,
 * RTCL_CHILD_EMPTY an empty leaf, any other negative c the leaf ~c, whose
 * blocks are given by leaf_begin pairs as in OctreeHeader.
 * 48 bytes. */
typedef struct OctreeNode {
  float split[4];        /* x, y, z; [3] unused */
  rtcl_i32 child[8];
} OctreeNode;

/* The box of one triangle block of an octree leaf (kernels/shared/octree.h:
 * a ray that misses it skips the block's eight tests): the box of the
 * block's triangles intersected with the leaf's cell widened as the
 * build's overlap test widens it (octree_widening), in the Bvh8Node bounds
 * order: lower x, y, z, upper x, y, z. Every hit of the block's triangles
 * inside the widened cell lies in it. 24 bytes. */
typedef struct BlockBox {
  float bounds[6];
} BlockBox;

/* The root of a pointer octree: its box, the root reference (an inner
 * node index, or a leaf or empty reference as in OctreeNode), and the
 * occupied space: occupied_bounds (Bvh8Node bounds layout) holds, per child
 * q of an inner root, the union of the BlockBoxes of the leaves below it
 * and of their spheres' boxes clipped to their widened cells (empty slot:
 * lower +inf, upper -inf); a leaf root has its box in slot 0 and the other
 * slots empty. Every hit inside a leaf's widened cell lies in its
 * octant's box. 240 bytes. */
typedef struct OctreePtrHeader {
  float occupied_bounds[6][RTCL_BLOCK_WIDTH]; /* first: float8 rows, 32-byte aligned */
  float lower[4];        /* [3] unused */
  float upper[4];        /* [3] unused */
  rtcl_i32 root;
  rtcl_u32 leaf_count;
  rtcl_i32 depth;        /* levels below the root */
  rtcl_i32 pad;
} OctreePtrHeader;

/* A BSP / kd-tree node (kernels/accel/kdtree.cl; built by
 * src/rtcl/accel/bsp.cpp and kdtree.cpp): 8 bytes, in depth-first order.
 * flags bits 0..1: the split axis 0, 1, 2 (x, y, z) of an inner node, or
 * RTCL_KD_LEAF. Inner node n: its child below the plane (coordinate <=
 * split) is node n + 1, its child above (>= split) is node flags >> 2, and
 * data holds the split coordinate's float bits. Leaf: its references are
 * refs[(flags >> 2) .. (flags >> 2) + data), triangles first as r >= 0 (lane
 * r & 7 of triangle block r >> 3, id-ordered blocks), then spheres as ~r < 0,
 * each kind in ascending order. Every index is < 2^30. Reference lanes (a
 * leaf's triangles load as contiguous float8 runs, as GridHeader's): row
 * 3 * vertex + axis of a float array with rows KdHeader.lane_stride apart
 * holds, at position k, that coordinate of the triangle of refs[k] (NaN
 * where refs[k] is a sphere, and in the 8 positions past the last
 * reference), and lane_prims[k] its primitive id (-1 there). */
typedef struct KdNode {
  rtcl_u32 flags;
  rtcl_u32 data;
} KdNode;
#define RTCL_KD_LEAF 3u
#define RTCL_KD_INNER(axis, above) ((rtcl_u32)(axis) | ((rtcl_u32)(above) << 2))
#define RTCL_KD_LEAF_NODE(first) (RTCL_KD_LEAF | ((rtcl_u32)(first) << 2))

/* The single-ray traversal's nodes (kernels/accel/kdtree.cl; built by
 * src/rtcl/accel/kdtree_fused.cpp from the KdNode array) are Bvh8Node
 * records, each a subtree of the kd-tree cut off at up to eight cells
 * (kd nodes whose cells tile the subtree root's cell, less empty leaves):
 * lane k's bounds are its cell's box shrunk to what it holds (a leaf: its
 * primitives clipped to the cell; an inner kd node: the union of its fused
 * node's lanes), and child[k] >= 0 is the fused node of an inner kd node,
 * < 0 the leaf ~child[k] of the KdNode array, RTCL_KD_NO_CELL an unused
 * lane (bounds lower = +inf, upper = -inf). */
#define RTCL_KD_NO_CELL 0x7fffffff

/* The tree's root box [lower, upper] (closed, float), which contains every
 * stored primitive; traversal clips the ray to it; and the rows' stride of
 * the reference lanes (KdNode). 48 bytes; element [3] of each row is
 * unused. */
typedef struct KdHeader {
  float lower[4];
  float upper[4];
  rtcl_i32 lane_stride; /* references + 8 */
  rtcl_i32 unused[3];
} KdHeader;

/* Two-level scenes (src/rtcl/scene/two_level.hpp, kernels/accel/instances.cl).
 * The top level is an array of Bvh8Node records over the instances' world
 * boxes (root: node 0) whose child references are an inner node (>= 0),
 * RTCL_CHILD_EMPTY, or instance k as ~k. The bottom levels, one 8-wide BVH
 * per mesh in the BVH structure's layout, are concatenated: mesh b's nodes,
 * triangle blocks and sphere blocks start at BottomLevel b's offsets (in
 * records), and its child references are relative to them. 16 bytes. */
typedef struct BottomLevel {
  rtcl_u32 node_offset, triangle_offset, sphere_offset;
  rtcl_u32 unused;
} BottomLevel;

/* One instance of a bottom level. A static one turns the world ray (o, d)
 * into its mesh's space as o' = to_object * (o - translation),
 * d' = to_object * d (float, in that order: o - translation is small for a
 * ray near the instance however far it lies), to_object being the inverse
 * of the linear part of its object-to-world transform (rows, the double
 * inverse rounded to float) and translation that transform's translation.
 * RTCL_INSTANCE_LINEAR_IDENTITY: to_object is exactly the identity and the
 * ray's direction is used as is; RTCL_INSTANCE_IDENTITY as well: the
 * translation is zero too, and the world ray is the object ray.
 * RTCL_INSTANCE_MOVING: the transform is InstanceMotion `motion`'s at the
 * ray's time (to_object and translation unused). user_id is what hits
 * report. 64 bytes. */
#define RTCL_INSTANCE_LINEAR_IDENTITY 1u
#define RTCL_INSTANCE_MOVING 2u
#define RTCL_INSTANCE_IDENTITY 4u
typedef struct InstanceRecord {
  float to_object[9];
  float translation[3];
  rtcl_u32 bottom;  /* index of its BottomLevel */
  rtcl_u32 user_id;
  rtcl_u32 flags;
  rtcl_u32 motion;  /* RTCL_INSTANCE_MOVING: index of its InstanceMotion */
} InstanceRecord;

/* A moving instance's object-to-world transforms at times 0 (open) and 1
 * (close), 3x4 row-major (x' = m[0] x + m[1] y + m[2] z + m[3], ...). At
 * time tau its transform is open + tau * (close - open), element by element
 * in float, so every point of the mesh moves on a straight line. 96 bytes. */
typedef struct InstanceMotion {
  float open[12];
  float close[12];
} InstanceMotion;

#ifndef __OPENCL_VERSION__
} /* namespace rtcl */
#endif
#endif
