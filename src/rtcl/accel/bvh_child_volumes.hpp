// The candidate filter volumes of one child slot of an 8-wide BVH node
// (the mixed-volume BVH, bvh_volumes.hpp): the exact (Welzl) bounding
// sphere, the 14-DOP's four body-diagonal slabs and the OBB of the
// triangle vertices below the child, each as the lane values its float8
// record stores (widened by the ray-independent part of its filter's
// rounding margin, rounded outward) and the area of the set the kernel
// then tests.
//
// Area of "box ∩ volume", the set a ray must meet to pass the box test and
// the filter (before the ray-dependent part of the margin):
//   - k-DOP and OBB: exact, the surface area of the polytope cut by the
//     child's float box slabs and the stored filter slabs
//     (measure_slabs, in double);
//   - sphere: min(area(box), area(sphere)), an upper bound (the
//     intersection lies in each, and a convex body inside another has the
//     smaller area), so a sphere's gain is never overstated.
// A kind whose area is not below the box's is not used for the slot (its
// lane passes the box's answer through).
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/aabb.hpp"
#include "rtcl/layouts.hpp"

namespace rtcl {

// Filter kinds, in RTCL_FILTER_* order (kernels/shared/layouts.h).
inline constexpr int kFilterKinds = 3;

struct ChildVolumes {
  double box_area = 0.0;               // the child's float box (world units^2)
  bool used[kFilterKinds] = {};        // kind k cuts the box (area[k] < box_area)
  double area[kFilterKinds] = {};      // area of box ∩ volume k, <= box_area
  float sphere[4] = {0, 0, 0, -1};     // centre, widened radius
  float kdop_near[RTCL_KDOP_FILTER_SLABS] = {}, kdop_far[RTCL_KDOP_FILTER_SLABS] = {};
  float obb_axis[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  float obb_near[3] = {}, obb_far[3] = {};
};

// Candidates for a child with box `box` over the triangle vertices
// `points` (non-empty, finite). Throws Error naming `source` for bad points.
ChildVolumes child_volumes(const Aabb& box, const std::vector<glm::vec3>& points, const std::string& source);

// Writes slot `lane` of each record: the candidate where it is used, else
// the pass-through values (sphere r = -1; slabs -FLT_MAX .. FLT_MAX).
void write_sphere_lane(Bvh8Spheres& record, int lane, const ChildVolumes* v);
void write_kdop_lane(Bvh8Kdop& record, int lane, const ChildVolumes* v);
void write_obb_lane(Bvh8Obb& record, int lane, const ChildVolumes* v);

}  // namespace rtcl
