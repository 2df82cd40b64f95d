#include "bench/support/scene_catalog.hpp"

#include <algorithm>
#include <cmath>

namespace rtcl::bench {

// Cameras and lights, in each file's own units and axes (all are y-up).
// bunny (0.16 units, faces +z) and dragon (14 units long, side view from +z):
// seen from the front, the model filling most of the square view. sponza:
// from the floor at one end of the atrium looking along it (x axis); sibenik:
// from the entrance end of the nave towards the apse (+x). teapot-stadium:
// the teapot from the front and above, inside its stadium. teapot, ogre and
// the Cornell box (open towards +z): fitted to their bounds.
const std::vector<SceneSpec>& scene_specs() {
  static const std::vector<SceneSpec> specs = {
      {"bunny", "stanford_bunny/bunny.obj",
       {{-0.0168f, 0.110f, 0.36f}, {-0.0168f, 0.110f, -0.0015f}, {0, 1, 0}, 30.0f},
       {0.15f, 0.35f, 0.30f}},
      {"dragon", "stanford_dragon_100k/dragon.obj",
       {{0.0f, 5.5f, 28.0f}, {0.0f, 4.97f, 0.0f}, {0, 1, 0}, 30.0f},
       {-10.0f, 20.0f, 20.0f}},
      {"sponza", "sponza/sponza.obj",
       {{13.0f, 2.0f, 0.0f}, {-10.0f, 4.0f, 0.0f}, {0, 1, 0}, 60.0f},
       {0.0f, 13.0f, 1.0f}},
      {"sibenik", "sibenik/sibenik.obj",
       {{-17.0f, -11.0f, 0.0f}, {0.0f, -9.0f, 0.0f}, {0, 1, 0}, 60.0f},
       {-2.0f, -3.0f, 0.0f}},
      // The teapot (6.4 units wide) in a box 100 times its size; the camera
      // sees it and the far walls around it.
      {"teapot-stadium", "teapot/teapot.obj",
       {{0.0f, 4.0f, 10.0f}, {0.2f, 1.4f, 0.0f}, {0, 1, 0}, 50.0f},
       {5.0f, 10.0f, 8.0f},
       100.0f,
       16384},
      {"teapot", "teapot/teapot.obj", {}, {}, 0.0f, 0, true},
      {"ogre", "ogre/ogre.obj", {}, {}, 0.0f, 0, true},
      {"cornell-box", "cornell_box/CornellBox-Original.obj", {}, {}, 0.0f, 0, true},
  };
  return specs;
}

const SceneSpec* find_scene_spec(const std::string& name) {
  const auto& specs = scene_specs();
  auto spec = std::find_if(specs.begin(), specs.end(), [&](const SceneSpec& s) { return s.name == name; });
  return spec == specs.end() ? nullptr : &*spec;
}

namespace {
// Radius of the sphere around the box (half its diagonal); never 0.
float bounding_radius(const Aabb& bounds) {
  float r = 0.5f * glm::length(bounds.extent());
  return r > 0.0f ? r : 1.0f;
}
}  // namespace

Camera fit_camera(const Aabb& bounds) {
  constexpr float fov_y_deg = 40.0f;
  glm::vec3 centre = bounds.center(), half = 0.5f * bounds.extent();
  // The box's front face (x by y), with a 10% margin, fills the view from
  // this far in front of it.
  float face = 1.1f * std::max({half.x, half.y, 1e-3f * bounding_radius(bounds)});
  float distance = half.z + face / std::tan(0.5f * glm::radians(fov_y_deg));
  glm::vec3 direction = glm::normalize(glm::vec3(0.0f, 0.3f, 1.0f));
  return Camera{centre + distance * direction, centre, {0.0f, 1.0f, 0.0f}, fov_y_deg};
}

glm::vec3 fit_light(const Aabb& bounds) {
  glm::vec3 direction = glm::normalize(glm::vec3(0.5f, 1.0f, 0.7f));
  return bounds.center() + 2.0f * bounding_radius(bounds) * direction;
}

}  // namespace rtcl::bench
