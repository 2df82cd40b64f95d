#include "rtcl/scene/scene_lights.hpp"

#include <algorithm>
#include <cstdio>

namespace rtcl {

namespace {

struct Emitters {
  std::size_t triangles = 0;
  double area = 0.0;
  glm::dvec3 emission_times_area{0.0};  // summed over the emitting triangles
};

// The emitting triangles of the scene's meshes at keyframe 0 (their
// transform), as expand_emissive_lights finds them: emission > 0 in some
// channel and a non-zero area.
Emitters emitters_of(const SceneDescription& scene) {
  Emitters out;
  auto emits = [&](std::uint32_t m) { return glm::any(glm::greaterThan(scene.materials[m].emission, glm::vec3(0.0f))); };
  for (const SceneMesh& mesh : scene.meshes) {
    const MeshShape& shape = *mesh.shape;
    if (std::none_of(shape.materials.begin(), shape.materials.end(), emits)) continue;
    for (std::size_t t = 0; t < shape.triangles.size(); ++t) {
      const glm::vec3 emission = scene.materials[shape.materials[t]].emission;
      if (!glm::any(glm::greaterThan(emission, glm::vec3(0.0f)))) continue;
      glm::dvec3 v[3];
      for (int k = 0; k < 3; ++k) v[k] = glm::dvec3(mesh.transform * glm::dvec4(glm::dvec3(shape.vertices[shape.triangles[t][k]]), 1.0));
      const double area = 0.5 * glm::length(glm::cross(v[1] - v[0], v[2] - v[0]));
      if (!(area > 0.0)) continue;
      ++out.triangles;
      out.area += area;
      out.emission_times_area += glm::dvec3(emission) * area;
    }
  }
  return out;
}

std::string number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", x);
  return text;
}

}  // namespace

LightNotice default_lights(SceneDescription& scene, bool area_lights, const std::string& point_lights_only) {
  LightNotice notice;
  if (!scene.lights.empty()) return notice;
  const Emitters e = emitters_of(scene);
  const std::string plural = e.triangles == 1 ? "" : "s";
  const std::string lit_by = "only emission and the ambient term light the image";
  if (e.triangles == 0) {
    if (!glm::any(glm::greaterThan(scene.ambient, glm::vec3(0.0f))))
      notice.warning = scene.source + ": no light declared and no triangle emits light: " + lit_by +
                       ", and the ambient term is 0 (\"lights\" declares lights)";
    return notice;
  }
  if (!area_lights) {
    notice.warning = scene.source + ": no light declared; " + point_lights_only + " lights by point lights only, so the " +
                     std::to_string(e.triangles) + " emissive triangle" + plural + " light nothing and " + lit_by;
    return notice;
  }
  const glm::dvec3 mean = e.emission_times_area / e.area;
  Light light;
  light.shape = LightShape::emissive;
  light.intensity = static_cast<float>(1.0 / std::max({mean.x, mean.y, mean.z}));
  scene.lights.push_back(light);
  notice.note = scene.source + ": no light declared: its " + std::to_string(e.triangles) + " emissive triangle" +
                plural + " light it as area lights, as {\"type\": \"emissive\", \"intensity\": " +
                number(light.intensity) + "} would (the brightest channel of their mean emission scaled to 1; " +
                "\"lights\" declares other lights)";
  return notice;
}

}  // namespace rtcl
