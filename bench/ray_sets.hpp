// Ray-set generation for the benchmark scenes: camera rays, and the shadow and
// diffuse-bounce rays spawned from the primary hits. Deterministic: the same
// scene and image size always give the same rays.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "bench_scenes.hpp"

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

// One shadow and one diffuse ray per primary ray that hit, in pixel order.
// The hit point is rebuilt from the triangle and (u, v); the normal faces the
// incoming ray. Diffuse directions come from a hash of the pixel index.
SecondaryRays secondary_rays(const Geometry& geometry, const RaySet& primary, const glm::vec3& light);

// A binary PPM of the primary hits (grey by the cosine to the camera, darker
// where the shadow ray is occluded, blue for misses): how the cameras and
// lights were checked. Written when $RTCL_BENCH_DUMP names a directory.
void write_preview(const std::string& path, const BenchScene& scene);

}  // namespace rtcl::bench
