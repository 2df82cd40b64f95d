#include "rtcl/scene/showcase_scene.hpp"

#include "rtcl/error.hpp"
#include "rtcl/scene/default_scene.hpp"
#include "rtcl/scene/forest_scene.hpp"

namespace rtcl {

namespace {

std::uint32_t add_material(SceneDescription& s, Material m) {
  s.materials.push_back(std::move(m));
  return static_cast<std::uint32_t>(s.materials.size() - 1);
}

std::uint32_t material_named(const SceneDescription& s, const std::string& name) {
  for (std::size_t i = 0; i < s.materials.size(); ++i)
    if (s.materials[i].name == name) return static_cast<std::uint32_t>(i);
  throw Error("internal: the default scene has no material " + name);
}

}  // namespace

SceneDescription showcase_scene() {
  SceneDescription s = default_scene();
  s.source = "showcase scene";
  // Soft shadows: a 0.5 x 0.5 quad light just below the ceiling panel.
  Light lamp;
  lamp.shape = LightShape::quad;
  lamp.position = {0.0f, 1.98f, 0.0f};
  lamp.edge1 = {0.5f, 0.0f, 0.0f};
  lamp.edge2 = {0.0f, 0.0f, 0.5f};
  lamp.color = {1.0f, 0.97f, 0.9f};
  s.lights = {lamp};
  // Glossy reflection: the mirror sphere becomes brushed metal.
  Material metal = s.materials.at(material_named(s, "mirror"));
  metal.name = "glossy metal";
  metal.diffuse = glm::vec3(0.05f);
  metal.kr = {0.85f, 0.8f, 0.7f};
  metal.roughness = 0.2f;
  s.spheres.at(0).material = add_material(s, metal);
  // Depth of field: a lens focused on the glass sphere (at (0.3, 0.3,
  // 0.45), 3.45 from the camera along the view), and a small red ball in
  // the foreground, 1.4 from the camera.
  s.camera.aperture = 0.04f;
  s.camera.focus_distance = 3.45f;
  Material red;
  red.name = "foreground red";
  red.diffuse = red.ambient = {0.7f, 0.1f, 0.08f};
  red.specular = glm::vec3(0.3f);
  red.shininess = 60.0f;
  s.spheres.push_back(SceneSphere::still({-0.32, 0.55, 2.3}, 0.12, add_material(s, red)));
  // Motion blur: a yellow ball crossing the room at mid-height.
  Material yellow;
  yellow.name = "moving yellow";
  yellow.diffuse = yellow.ambient = {0.9f, 0.6f, 0.02f};
  yellow.specular = glm::vec3(0.2f);
  SceneSphere ball = SceneSphere::still({-0.55, 1.25, 0.2}, 0.15, add_material(s, yellow));
  ball.moving = true;
  ball.end_center = ball.center + glm::dvec3(0.4, 0.1, 0.0);
  ball.end_radius = ball.radius;
  ball.motion_key = "showcase scene: the yellow ball's motion";
  s.spheres.push_back(ball);
  return s;
}

SceneDescription builtin_scene(const std::string& name, const std::string& scenes_dir) {
  if (name == "default") return default_scene();
  if (name == "showcase") return showcase_scene();
  if (name == "forest") {
    if (scenes_dir.empty())
      throw Error("builtin_scene name \"forest\": the forest reads the Stanford bunny from the scenes directory "
                  "(stanford_bunny/bunny.obj in it), and none is given (RTCL_SCENES_DIR names it)");
    return forest_scene(scenes_dir + "/stanford_bunny/bunny.obj");
  }
  throw Error("builtin_scene name \"" + name + "\": unknown built-in scene (known: default, showcase, forest)");
}

}  // namespace rtcl
