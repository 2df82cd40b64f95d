// "bvh-mixed": the binned-SAH 8-wide BVH of "bvh" with a per-node choice of
// bounding volume (bvh_volumes.hpp): boxes alone, or boxes then bounding
// spheres, 14-DOP diagonal slabs or oriented boxes. Traced one ray per
// work-item (kernels/accel/bvh.cl, compiled with RTCL_BVH_SPHERES,
// RTCL_BVH_KDOP, RTCL_BVH_OBB for the kinds some node uses), for coherent
// calls too: the packet kernel has no filters.
#pragma once

#include <memory>

#include "rtcl/accel.hpp"
#include "rtcl/accel/bvh_volumes.hpp"

namespace rtcl {

// Options: those of "bvh", plus sphere_cost, kdop_cost, obb_cost and
// block_cost (VolumeCosts).
const StructureSpec& bvh_mixed_structure();

std::unique_ptr<Accel> make_bvh_mixed(const Device& device, const Geometry& geometry, const AccelConfig& config);

}  // namespace rtcl
