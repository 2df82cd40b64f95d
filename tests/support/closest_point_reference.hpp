// Double-precision brute-force reference of the closest-point query
// (Accel::closest_points), and the rule that decides whether a device answer
// is right. Tolerances scale with the scene and the point (no absolute
// epsilons).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/geometry.hpp"
#include "rtcl/queries.hpp"

namespace rtcl::test {

struct PointPrim {
  glm::dvec3 point{0.0};  // nearest point of the primitive
  double distance = 0.0;
  double u = 0.0, v = 0.0;  // triangle barycentrics as in Hit (weights of v1, v2); 0 for spheres
};

// Nearest point of one primitive (triangle ids first, then spheres) in
// double: Ericson, Real-Time Collision Detection 5.1.5 for triangles;
// centre + r * unit(p - c) for spheres (a point at the centre: centre + (r, 0, 0)).
PointPrim reference_point_prim(const Geometry& geometry, std::uint32_t prim, const glm::dvec3& p);

struct ReferencePoint {
  double distance = 0.0;  // +inf when nothing lies within the radius
  std::int32_t prim = -1; // smallest id at exactly that distance; -1: none
};

// Brute force over every primitive (zero-area triangles skipped, as the
// structures do), within max_distance.
ReferencePoint reference_closest_point(const Geometry& geometry, const glm::dvec3& p,
                                       double max_distance = std::numeric_limits<double>::infinity());
std::vector<ReferencePoint> reference_closest_points(const Geometry& geometry, const std::vector<glm::vec3>& points,
                                                     double max_distance = std::numeric_limits<double>::infinity());

// The spatial tolerance for a point: `ulps` float epsilons of the larger of
// the scene's extent, its coordinates' magnitude and the point's.
double closest_point_tolerance(const Aabb& bounds, const glm::dvec3& p, double ulps = 64.0);

// "" when the device's answer for point p is acceptable: its distance within
// tolerance of the reference's; its point on its primitive, at its distance
// from p and equal to its barycentric point (all within tolerance); its
// primitive no farther than the reference's by more than the tolerance.
// Near max_distance (within tolerance) a miss and a hit are both accepted.
std::string judge_closest_point(const Geometry& geometry, const Aabb& bounds, const glm::dvec3& p,
                                const PointHit& device, const ReferencePoint& reference,
                                double max_distance = std::numeric_limits<double>::infinity());

// judge_closest_point over all points; up to `report` failure descriptions
// (the total count in *failures).
std::vector<std::string> judge_closest_points(const Geometry& geometry, const std::vector<glm::vec3>& points,
                                              const std::vector<PointHit>& device,
                                              const std::vector<ReferencePoint>& reference, std::size_t* failures,
                                              double max_distance = std::numeric_limits<double>::infinity(),
                                              std::size_t report = 5);

}  // namespace rtcl::test
