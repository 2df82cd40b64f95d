#include "rtcl/scene/default_scene.hpp"

#include <glm/gtc/matrix_transform.hpp>

namespace rtcl {

namespace {

enum MaterialId : std::uint32_t { white, red, green, panel, mirror, glass };

std::vector<Material> materials() {
  auto diffuse = [](const char* name, glm::vec3 colour) {
    Material m;
    m.name = name;
    m.ambient = colour;
    m.diffuse = colour;
    return m;
  };
  Material light_panel;
  light_panel.name = "panel";
  light_panel.diffuse = glm::vec3(0.0f);
  light_panel.emission = glm::vec3(3.0f, 2.8f, 2.5f);
  Material mirror_m;
  mirror_m.name = "mirror";
  mirror_m.diffuse = glm::vec3(0.02f);
  mirror_m.specular = glm::vec3(0.5f);
  mirror_m.shininess = 200.0f;
  mirror_m.kr = glm::vec3(0.9f);
  Material glass_m;
  glass_m.name = "glass";
  glass_m.diffuse = glm::vec3(0.0f);
  glass_m.specular = glm::vec3(0.6f);
  glass_m.shininess = 300.0f;
  glass_m.kt = glm::vec3(1.0f);
  glass_m.ior = 1.5f;
  // Same order as MaterialId.
  return {diffuse("white", {0.725f, 0.71f, 0.68f}), diffuse("red", {0.63f, 0.065f, 0.05f}),
          diffuse("green", {0.14f, 0.45f, 0.091f}), light_panel, mirror_m, glass_m};
}

// Appends the quad a b c d (a convex polygon in order) as two triangles,
// wound so that their normal points along `outward`.
void add_quad(MeshShape& mesh, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, glm::vec3 outward,
              std::uint32_t material) {
  if (glm::dot(glm::cross(b - a, c - a), outward) < 0.0f) std::swap(b, d);
  auto base = static_cast<std::uint32_t>(mesh.vertices.size());
  mesh.vertices.insert(mesh.vertices.end(), {a, b, c, d});
  mesh.triangles.push_back({base, base + 1, base + 2});
  mesh.triangles.push_back({base, base + 2, base + 3});
  mesh.materials.insert(mesh.materials.end(), 2, material);
}

SceneMesh room() {
  SceneMesh out;
  out.name = "room";
  MeshShape& m = out.edit_shape();
  const glm::vec3 up(0, 1, 0), right(1, 0, 0), front(0, 0, 1);
  // Faces point into the room (the side the camera sees).
  add_quad(m, {-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}, up, white);      // floor
  add_quad(m, {-1, 2, -1}, {1, 2, -1}, {1, 2, 1}, {-1, 2, 1}, -up, white);     // ceiling
  add_quad(m, {-1, 0, -1}, {1, 0, -1}, {1, 2, -1}, {-1, 2, -1}, front, white); // back wall
  add_quad(m, {-1, 0, -1}, {-1, 0, 1}, {-1, 2, 1}, {-1, 2, -1}, right, red);   // left wall
  add_quad(m, {1, 0, -1}, {1, 0, 1}, {1, 2, 1}, {1, 2, -1}, -right, green);    // right wall
  const float h = 1.995f, s = 0.25f;
  add_quad(m, {-s, h, -s}, {s, h, -s}, {s, h, s}, {-s, h, s}, -up, panel);      // light panel
  return out;
}

// A unit cube [-0.5, 0.5]^3 with outward faces; placed by its transform.
SceneMesh glass_block() {
  SceneMesh out;
  out.name = "glass block";
  MeshShape& m = out.edit_shape();
  for (int axis = 0; axis < 3; ++axis)
    for (float side : {-0.5f, 0.5f}) {
      glm::vec3 n(0.0f), u(0.0f), v(0.0f);
      n[axis] = side;
      u[(axis + 1) % 3] = 0.5f;
      v[(axis + 2) % 3] = 0.5f;
      add_quad(m, n - u - v, n + u - v, n + u + v, n - u + v, n, glass);
    }
  // 0.4 x 0.8 x 0.4, standing 0.002 above the floor (coplanar faces would
  // make the closest hit between block and floor arbitrary).
  glm::dmat4 t = glm::translate(glm::dmat4(1.0), glm::dvec3(0.42, 0.402, -0.45));
  t = glm::rotate(t, glm::radians(25.0), glm::dvec3(0, 1, 0));
  out.transform = glm::scale(t, glm::dvec3(0.4, 0.8, 0.4));
  return out;
}

}  // namespace

SceneDescription default_scene() {
  SceneDescription s;
  s.source = "default scene";
  s.camera.position = {0.0f, 1.0f, 3.9f};
  s.camera.look_at = {0.0f, 1.0f, 0.0f};
  s.camera.up = {0.0f, 1.0f, 0.0f};
  s.camera.fov_deg = 39.3f;
  s.camera.aspect = 1.0f;
  s.ambient = glm::vec3(0.1f);
  s.background = glm::vec3(0.0f);
  s.lights.push_back(PointLight{{0.1f, 1.85f, 0.45f}, {1.0f, 0.97f, 0.9f}, 1.0f});
  s.materials = materials();
  s.meshes.push_back(room());
  s.meshes.push_back(glass_block());
  s.spheres.push_back(SceneSphere::still({-0.45, 0.42, -0.3}, 0.42, mirror));
  s.spheres.push_back(SceneSphere::still({0.3, 0.3, 0.45}, 0.3, glass));
  return s;
}

}  // namespace rtcl
