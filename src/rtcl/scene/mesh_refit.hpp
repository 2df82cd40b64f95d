// Refit of a scene's bottom level (internal; Scene::update_vertices and
// Scene::commit, rtcl/scene.hpp): a mesh whose vertices moved over the same
// triangles keeps its tree. Its host image (MeshBuild) is copied and
// refitted on host threads (refit_bvh8, src/rtcl/accel/refit.hpp), under
// the rules of Accel::refit: a triangle skipped at the build for zero area
// that has an area now, or a SAH cost past RefitPolicy::max_cost_ratio
// times the build's, asks for a rebuild instead.
//
// On the host rather than on the device (Accel::refit's Bvh8Refit):
// committed bottom levels are immutable (queries of the previous commit
// may still run on them, and a failed commit must leave them), so a refit
// writes new buffers whichever side computes it, and the scene keeps every
// mesh's host image for the next commit's uploads and world boxes; the
// host refit writes that image directly, where a device refit would also
// read it back.
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/scene/two_level.hpp"

namespace rtcl {

// What refit_mesh gives: the refitted bottom level, or none and why a
// rebuild is needed.
struct MeshRefit {
  std::shared_ptr<const MeshBuild> build;
  std::string reason;
};

// `built` moved to `moved` (the same triangles and spheres, new vertices,
// validated by the caller).
MeshRefit refit_mesh(const MeshBuild& built, std::shared_ptr<const Geometry> moved, const RefitPolicy& policy);

// The bottom levels of `meshes` on the device when each is
// previous_meshes' mesh at the same index or, where refitted[k], a refit
// of it (the same node and block counts): previous's nodes and triangle
// blocks copied on the device, the refitted meshes' ranges written from
// their images, its offsets and sphere blocks shared. Null where the
// layouts differ (the caller uploads them all, upload_bottoms).
std::shared_ptr<const DeviceBottoms> refit_bottoms(const Device& device, const DeviceBottoms& previous,
                                                   std::span<const std::shared_ptr<const MeshBuild>> previous_meshes,
                                                   std::span<const std::shared_ptr<const MeshBuild>> meshes,
                                                   const std::vector<bool>& refitted);

}  // namespace rtcl
