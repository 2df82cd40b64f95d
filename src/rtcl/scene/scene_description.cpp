#include "rtcl/scene/scene_description.hpp"

#include <cmath>
#include <unordered_set>

#include "rtcl/error.hpp"

namespace rtcl {

namespace {

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void check_colour(const SceneDescription& scene, const std::string& where, const glm::vec3& c) {
  if (!finite(c) || c.x < 0.0f || c.y < 0.0f || c.z < 0.0f)
    throw Error(scene.source + ": " + where + " must be finite and not negative");
}

void check_unit(const SceneDescription& scene, const std::string& where, const glm::vec3& c) {
  check_colour(scene, where, c);
  if (c.x > 1.0f || c.y > 1.0f || c.z > 1.0f) throw Error(scene.source + ": " + where + " must lie in [0, 1]");
}

void validate_camera(const SceneDescription& scene) {
  const Camera& c = scene.camera;
  std::string where = scene.source + ": camera: ";
  if (!finite(c.position) || !finite(c.look_at) || !finite(c.up) || !std::isfinite(c.fov_deg) ||
      !std::isfinite(c.aspect))
    throw Error(where + "numbers must be finite");
  glm::dvec3 view = glm::dvec3(c.look_at) - glm::dvec3(c.position);
  if (glm::length(view) == 0.0) throw Error(where + "position and look_at are the same point");
  if (glm::length(glm::cross(glm::normalize(view), glm::dvec3(c.up))) < 1e-6)
    throw Error(where + "up is zero or parallel to the view direction");
  if (!(c.fov_deg > 0.0f && c.fov_deg < 180.0f)) throw Error(where + "fov must lie in (0, 180) degrees");
  if (c.aspect < 0.0f) throw Error(where + "aspect must be positive");
  if (!std::isfinite(c.aperture) || c.aperture < 0.0f)
    throw Error(where + "aperture must be finite and not negative (got " + std::to_string(c.aperture) + ")");
  if (!std::isfinite(c.focus_distance) || c.focus_distance < 0.0f)
    throw Error(where + "focus_distance must be positive (got " + std::to_string(c.focus_distance) + ")");
}

void validate_material(const SceneDescription& scene, std::size_t i) {
  const Material& m = scene.materials[i];
  std::string where = "material '" + m.name + "' ";
  check_colour(scene, where + "ambient", m.ambient);
  check_colour(scene, where + "diffuse", m.diffuse);
  check_colour(scene, where + "specular", m.specular);
  check_colour(scene, where + "emission", m.emission);
  check_unit(scene, where + "kr", m.kr);
  check_unit(scene, where + "kt", m.kt);
  if (!std::isfinite(m.shininess) || m.shininess < 0.0f)
    throw Error(scene.source + ": " + where + "shininess must be finite and not negative");
  if (!std::isfinite(m.ior) || !(m.ior > 0.0f))
    throw Error(scene.source + ": " + where + "ior must be positive (got " + std::to_string(m.ior) + ")");
  if (!(m.roughness >= 0.0f && m.roughness <= 1.0f))
    throw Error(scene.source + ": " + where + "roughness must lie in [0, 1] (got " + std::to_string(m.roughness) + ")");
}

void validate_light(const SceneDescription& scene, std::size_t i) {
  const Light& l = scene.lights[i];
  std::string where = scene.source + ": lights[" + std::to_string(i) + "] ";
  if (!finite(l.position)) throw Error(where + "position must be finite");
  check_colour(scene, "lights[" + std::to_string(i) + "] color", l.color);
  if (!std::isfinite(l.intensity) || l.intensity < 0.0f) throw Error(where + "intensity must be finite and not negative");
  if (!finite(l.edge1) || !finite(l.edge2)) throw Error(where + "edge1 and edge2 must be finite");
  if (!std::isfinite(l.radius) || l.radius < 0.0f)
    throw Error(where + "radius must be finite and not negative (got " + std::to_string(l.radius) + ")");
  if (l.shape == LightShape::disc && (!finite(l.normal) || glm::length(glm::dvec3(l.normal)) == 0.0))
    throw Error(where + "normal of a disc light must be finite and not zero");
}

glm::vec3 apply_point(const glm::dmat4& m, const glm::vec3& p) { return glm::vec3(m * glm::dvec4(glm::dvec3(p), 1.0)); }

}  // namespace

double similarity_scale(const glm::dmat4& t, const std::string& what) {
  glm::dmat3 a(t);
  double s = std::cbrt(std::abs(glm::determinant(a)));
  glm::dmat3 r = glm::transpose(a) * a;  // s^2 * identity for a similarity
  bool ok = std::isfinite(s) && s > 0.0 && t[0][3] == 0.0 && t[1][3] == 0.0 && t[2][3] == 0.0 && t[3][3] == 1.0;
  for (int i = 0; ok && i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (std::abs(r[i][j] - (i == j ? s * s : 0.0)) > 1e-9 * s * s) ok = false;
  if (!ok) throw Error(what + ": the transform must be a rotation, uniform scale and translation");
  return s;
}

void validate(const SceneDescription& scene) {
  validate_camera(scene);
  check_colour(scene, "ambient", scene.ambient);
  check_colour(scene, "background", scene.background);
  for (std::size_t i = 0; i < scene.lights.size(); ++i) validate_light(scene, i);
  for (std::size_t i = 0; i < scene.materials.size(); ++i) validate_material(scene, i);
  std::unordered_set<const MeshShape*> checked;
  for (const SceneMesh& mesh : scene.meshes) {
    if (!mesh.shape) throw Error(scene.source + ": mesh " + mesh.name + ": no shape");
    if (!checked.insert(mesh.shape.get()).second) continue;
    if (mesh.materials().size() != mesh.triangles().size())
      throw Error(scene.source + ": mesh " + mesh.name + ": one material per triangle expected");
    for (std::uint32_t m : mesh.materials())
      if (m >= scene.materials.size())
        throw Error(scene.source + ": mesh " + mesh.name + ": material index " + std::to_string(m) + " out of range");
  }
  for (std::size_t i = 0; i < scene.spheres.size(); ++i) {
    const SceneSphere& s = scene.spheres[i];
    if (s.material >= scene.materials.size())
      throw Error(scene.source + ": sphere " + std::to_string(i) + ": material index out of range");
    if (!std::isfinite(s.radius) || !(s.radius > 0.0) || !std::isfinite(s.center.x + s.center.y + s.center.z))
      throw Error(scene.source + ": sphere " + std::to_string(i) + " needs a finite centre and a positive radius");
  }
  if (scene.meshes.empty() && scene.spheres.empty()) throw Error(scene.source + ": the scene has no mesh and no sphere");
}

bool shares_meshes(const SceneDescription& scene) {
  std::unordered_set<const MeshShape*> seen;
  for (const SceneMesh& mesh : scene.meshes)
    if (!seen.insert(mesh.shape.get()).second) return true;
  return false;
}

SceneDescription unshare_meshes(const SceneDescription& scene) {
  SceneDescription out = scene;
  for (SceneMesh& mesh : out.meshes) mesh.edit_shape();
  return out;
}

FlatScene flatten(const SceneDescription& scene) {
  validate(scene);
  FlatScene flat;
  flat.geometry.source = scene.source;
  for (const SceneMesh& mesh : scene.meshes) {
    auto base = static_cast<std::uint32_t>(flat.geometry.vertices.size());
    // A mirroring transform reverses the winding: swap two corners so that
    // faces keep facing outward (refraction tells inside from outside by it).
    bool mirrored = glm::determinant(glm::dmat3(mesh.transform)) < 0.0;
    for (const glm::vec3& v : mesh.vertices()) flat.geometry.vertices.push_back(apply_point(mesh.transform, v));
    for (std::size_t t = 0; t < mesh.triangles().size(); ++t) {
      glm::uvec3 tri = mesh.triangles()[t] + glm::uvec3(base);
      if (mirrored) std::swap(tri.y, tri.z);
      flat.geometry.triangles.push_back(tri);
      flat.material.push_back(mesh.materials()[t]);
    }
  }
  for (const SceneSphere& s : scene.spheres) {
    flat.geometry.spheres.push_back(Sphere{glm::vec3(s.center), static_cast<float>(s.radius)});
    flat.material.push_back(s.material);
  }
  validate(flat.geometry);
  return flat;
}

std::vector<Light> expand_emissive_lights(const SceneDescription& scene, const FlatScene& flat) {
  std::vector<Light> out;
  const Geometry& g = flat.geometry;
  for (std::size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    if (l.shape != LightShape::emissive) {
      out.push_back(l);
      continue;
    }
    struct Emitter {
      glm::dvec3 v0, e1, e2;
      glm::vec3 emission;
      double area;
    };
    std::vector<Emitter> emitters;
    double total = 0.0;
    for (std::size_t t = 0; t < g.triangles.size(); ++t) {
      const Material& m = scene.materials[flat.material[t]];
      if (!glm::any(glm::greaterThan(m.emission, glm::vec3(0.0f)))) continue;
      glm::dvec3 v0(g.vertices[g.triangles[t][0]]), v1(g.vertices[g.triangles[t][1]]), v2(g.vertices[g.triangles[t][2]]);
      double area = 0.5 * glm::length(glm::cross(v1 - v0, v2 - v0));
      if (!(area > 0.0)) continue;
      emitters.push_back({v0, v1 - v0, v2 - v0, m.emission, area});
      total += area;
    }
    if (emitters.empty())
      throw Error(scene.source + ": lights[" + std::to_string(i) +
                  "]: an emissive light, but no triangle's material has emission > 0");
    for (const Emitter& e : emitters) {
      Light t;
      t.shape = LightShape::triangle;
      t.position = glm::vec3(e.v0);
      t.edge1 = glm::vec3(e.e1);
      t.edge2 = glm::vec3(e.e2);
      t.color = glm::vec3(glm::dvec3(e.emission) * glm::dvec3(l.color) * (e.area / total));
      t.intensity = l.intensity;
      out.push_back(t);
    }
  }
  return out;
}

SceneDescription transform_scene(const SceneDescription& scene, const glm::dmat4& t) {
  double s = similarity_scale(t, scene.source);
  SceneDescription out = scene;
  out.camera.position = apply_point(t, scene.camera.position);
  out.camera.look_at = apply_point(t, scene.camera.look_at);
  out.camera.up = glm::vec3(glm::dmat3(t) * glm::dvec3(scene.camera.up) / s);
  out.camera.aperture = static_cast<float>(scene.camera.aperture * s);
  out.camera.focus_distance = static_cast<float>(scene.camera.focus_distance * s);
  for (Light& l : out.lights) {
    l.position = apply_point(t, l.position);
    l.edge1 = glm::vec3(glm::dmat3(t) * glm::dvec3(l.edge1));
    l.edge2 = glm::vec3(glm::dmat3(t) * glm::dvec3(l.edge2));
    l.normal = glm::vec3(glm::dmat3(t) * glm::dvec3(l.normal) / s);
    l.radius = static_cast<float>(l.radius * s);
  }
  for (SceneMesh& m : out.meshes) {
    m.transform = t * m.transform;
    if (m.end_transform) m.end_transform = t * *m.end_transform;
  }
  for (SceneSphere& sp : out.spheres) {
    sp.center = glm::dvec3(t * glm::dvec4(sp.center, 1.0));
    sp.radius *= s;
    sp.end_center = glm::dvec3(t * glm::dvec4(sp.end_center, 1.0));
    sp.end_radius *= s;
  }
  return out;
}

}  // namespace rtcl
