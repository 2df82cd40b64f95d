// The pinhole camera's rays for an image (square pixels; the image's width /
// height is the aspect ratio that is rendered).
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "rtcl/scene/scene_description.hpp"

namespace rtcl {

// The ray through image position (x, y) (pixels, y down, (0, 0) the top-left
// corner of the image) starts at origin with direction corner + x du + y dv
// (not unit length). Computed in double.
struct CameraFrame {
  glm::dvec3 origin, corner, du, dv;
};
CameraFrame camera_frame(const Camera& camera, std::uint32_t width, std::uint32_t height);

// The image height for `width` when none is asked for: width / camera.aspect
// when the scene states an aspect, else width (square).
std::uint32_t default_height(const Camera& camera, std::uint32_t width);

}  // namespace rtcl
