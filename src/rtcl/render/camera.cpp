#include "rtcl/render/camera.hpp"

#include <algorithm>
#include <cmath>

namespace rtcl {

CameraFrame camera_frame(const Camera& camera, std::uint32_t width, std::uint32_t height) {
  glm::dvec3 position(camera.position);
  glm::dvec3 forward = glm::normalize(glm::dvec3(camera.look_at) - position);
  glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(camera.up)));
  glm::dvec3 up = glm::cross(right, forward);
  double half_h = std::tan(glm::radians(static_cast<double>(camera.fov_deg)) * 0.5);
  double half_w = half_h * static_cast<double>(width) / static_cast<double>(height);
  CameraFrame f;
  f.origin = position;
  f.corner = forward - half_w * right + half_h * up;
  f.du = right * (2.0 * half_w / width);
  f.dv = -up * (2.0 * half_h / height);
  return f;
}

std::uint32_t default_height(const Camera& camera, std::uint32_t width) {
  if (!(camera.aspect > 0.0f)) return width;
  double h = std::round(static_cast<double>(width) / camera.aspect);
  return static_cast<std::uint32_t>(std::clamp(h, 1.0, 1e9));
}

}  // namespace rtcl
