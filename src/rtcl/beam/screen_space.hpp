// The viewing beam made a prism (lecture, 光束跟踪: "将景物从景物坐标系变换到
// 屏幕坐标系 ... 视域棱锥变为柱体"): every triangle is clipped by the near
// plane in world space (before the perspective divide), projected to image
// pixels, and clipped to the screen rectangle, in double precision.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/render/camera.hpp"
#include "rtcl/geometry.hpp"

namespace rtcl::beam {

struct ScreenPolygon {
  std::vector<glm::dvec2> v;  // pixels, x right, y down; strictly convex, counter-clockwise in (x, y); 3 .. 8 vertices
  // 1 / s = inv_depth.x * x + inv_depth.y * y + inv_depth.z over the
  // triangle's plane, s the depth along the view direction (scene units).
  glm::dvec3 inv_depth{0.0};
  std::uint32_t prim = 0;  // triangle id in the geometry
};

struct ScreenSpace {
  CameraFrame frame;
  glm::dvec3 forward{0.0};  // unit view direction: frame.corner + (W/2) du + (H/2) dv
  std::uint32_t width = 0, height = 0;
  // Near plane, scene units: near_fraction times the largest distance from
  // the eye to a corner of the scene's box. What lies nearer is not seen.
  double near = 0.0;
};
inline constexpr double near_fraction = 1e-6;

ScreenSpace screen_space(const CameraFrame& frame, std::uint32_t width, std::uint32_t height, const Geometry& geometry);

// Pixel coordinates of world point p (in front of the eye) and its depth s.
glm::dvec2 project(const ScreenSpace& screen, const glm::dvec3& p, double* depth = nullptr);
// The point of the plane 1/s = inv_depth(x, y) seen through pixel position (x, y).
glm::dvec3 unproject(const ScreenSpace& screen, const glm::dvec3& inv_depth, const glm::dvec2& xy);

// The geometry's triangles as seen through the screen; triangles behind the
// near plane, outside the screen, seen edge-on or of projected area below
// 1e-12 of the screen are left out. Spheres are not polygons: the caller
// refuses them (render/beam_renderer.hpp).
//
// A reflected or refracted beam's world (mirror.hpp, refraction.hpp): every
// vertex is first moved by `to_world` (the product of the beam tree's M_r
// and M_t), and the triangles are clipped, like by the near plane, to
// keep_plane . (p, 1) >= keep_margin (the far side of the last interface;
// the margin, in scene units, drops the interface itself and polygons in
// its plane).
std::vector<ScreenPolygon> screen_polygons(const ScreenSpace& screen, const Geometry& geometry,
                                           const glm::dmat4& to_world = glm::dmat4(1.0),
                                           const glm::dvec4* keep_plane = nullptr, double keep_margin = 0.0);
// The same for triangle t alone: false when it is left out.
bool screen_polygon(const ScreenSpace& screen, const Geometry& geometry, std::uint32_t t, const glm::dmat4& to_world,
                    const glm::dvec4* keep_plane, double keep_margin, ScreenPolygon* out);

}  // namespace rtcl::beam
