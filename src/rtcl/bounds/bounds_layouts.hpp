// Host view of the bounding-volume records shared with the kernels
// (kernels/shared/bounds_layouts.h).
#pragma once

#include <glm/glm.hpp>

#include "rtcl/layouts.hpp"
#include "rtcl/shared/bounds_layouts.h"

namespace rtcl {

// The record of `count` slabs {x : d_near[i] <= dot(normal[i], x) <=
// d_far[i]} over contents within `reach` of the origin (SlabVolume).
SlabVolume slab_record(int count, const glm::vec3* normal, const float* d_near, const float* d_far, float reach);

}  // namespace rtcl
