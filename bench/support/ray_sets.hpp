// The benchmark ray sets: camera rays, and the shadow and diffuse-bounce
// rays spawned from the primary hits. Deterministic: the same scene, image
// size and primary hits always give the same rays. Shared by bench/ and
// `rtcl bench`.
#pragma once

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "bench/support/scene_catalog.hpp"
#include "rtcl/layouts.hpp"
#include "rtcl/geometry.hpp"

namespace rtcl::bench {

// One ray per pixel centre, rows top to bottom; unit directions, t in [0, inf).
std::vector<Ray> primary_rays(const Camera& camera, int width, int height);

// Distance a secondary ray's origin moves off its surface along the facing
// geometric normal: 1e-4 of the point's largest coordinate (~800 float ulps
// there), floored at 1e-6 of the scene's extent for points near the origin.
float spawn_offset(const glm::vec3& point, float scene_extent);

struct SecondaryRays {
  std::vector<Ray> shadow;   // towards `light`: dir = light - origin, t in [0, 1]
  std::vector<Ray> diffuse;  // unit cosine-distributed directions, t in [0, inf)
};

// One shadow and one diffuse ray per primary ray that hit (hits[i] answers
// primary[i]), in pixel order. The hit point is rebuilt from the triangle
// and (u, v); the normal faces the incoming ray. A sphere hit spawns from
// the point at t on the ray, with the sphere's normal there. Diffuse
// directions come from a hash of the pixel index. Throws Error when a hit
// names a primitive beyond the geometry.
SecondaryRays secondary_rays(const Geometry& geometry, std::span<const Ray> primary, std::span<const Hit> hits,
                             const glm::vec3& light);

}  // namespace rtcl::bench
