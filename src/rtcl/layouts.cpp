// Compile-time proof that the host sees the layouts the kernels use; the
// device side is proved at run time by kernels/probe/layout_probe.cl.
#include "rtcl/layouts.hpp"

#include <cstddef>

namespace rtcl {

static_assert(sizeof(Ray) == 32 && alignof(Ray) == 4);
static_assert(offsetof(Ray, ox) == 0 && offsetof(Ray, dx) == 12 && offsetof(Ray, tmin) == 24 &&
              offsetof(Ray, tmax) == 28);
static_assert(sizeof(Hit) == 16 && alignof(Hit) == 4);
static_assert(offsetof(Hit, t) == 0 && offsetof(Hit, u) == 4 && offsetof(Hit, v) == 8 && offsetof(Hit, prim) == 12);
static_assert(sizeof(PointHit) == 32 && alignof(PointHit) == 4);
static_assert(offsetof(PointHit, distance) == 12 && offsetof(PointHit, u) == 16 && offsetof(PointHit, prim) == 24);
static_assert(sizeof(TriangleBlock) == 320 && offsetof(TriangleBlock, prim) == 288);
static_assert(sizeof(SphereBlock) == 160 && offsetof(SphereBlock, r) == 96 && offsetof(SphereBlock, prim) == 128);
static_assert(sizeof(Bvh8Node) == 224 && offsetof(Bvh8Node, child) == 192);
static_assert(sizeof(Bvh8Node) % 32 == 0, "nodes must start on float8 boundaries");
static_assert(sizeof(Bvh8Spheres) == 128 && offsetof(Bvh8Spheres, cz) == 64 && offsetof(Bvh8Spheres, r) == 96);
static_assert(sizeof(Bvh8Kdop) == 256 && offsetof(Bvh8Kdop, d_far) == 128);
static_assert(sizeof(Bvh8Obb) == 480 && offsetof(Bvh8Obb, d_near) == 288 && offsetof(Bvh8Obb, d_far) == 384);
static_assert(sizeof(Bvh8Kdop) % 32 == 0 && sizeof(Bvh8Obb) % 32 == 0, "filter records hold float8 rows");
static_assert(RTCL_FILTER_KIND(RTCL_FILTER_REF(RTCL_FILTER_OBB, 5)) == RTCL_FILTER_OBB &&
              RTCL_FILTER_INDEX(RTCL_FILTER_REF(RTCL_FILTER_OBB, 5)) == 5);
static_assert(sizeof(GridHeader) == 272 && offsetof(GridHeader, occupied_bounds) == 0 &&
              offsetof(GridHeader, lower) == 192 && offsetof(GridHeader, cell) == 208 &&
              offsetof(GridHeader, res) == 224 && offsetof(GridHeader, macro) == 240 &&
              offsetof(GridHeader, lane_stride) == 256);
static_assert(sizeof(OctreeHeader) == 32 && offsetof(OctreeHeader, cell) == 16 && offsetof(OctreeHeader, top_digits) == 28);
static_assert(sizeof(OctreeNode) == 48 && offsetof(OctreeNode, child) == 16);
static_assert(sizeof(BlockBox) == 24);
static_assert(sizeof(OctreePtrHeader) == 240 && offsetof(OctreePtrHeader, lower) == 192 &&
              offsetof(OctreePtrHeader, root) == 224);
static_assert(sizeof(KdNode) == 8 && offsetof(KdNode, data) == 4);
static_assert(sizeof(KdHeader) == 48 && offsetof(KdHeader, upper) == 16 && offsetof(KdHeader, lane_stride) == 32);
static_assert(sizeof(BottomLevel) == 16 && offsetof(BottomLevel, sphere_offset) == 8);
static_assert(sizeof(InstanceRecord) == 64 && offsetof(InstanceRecord, translation) == 36 &&
              offsetof(InstanceRecord, bottom) == 48 && offsetof(InstanceRecord, motion) == 60);
static_assert(sizeof(InstanceMotion) == 96 && offsetof(InstanceMotion, close) == 48);

}  // namespace rtcl
