#include "rtcl/render/device_scene.hpp"

#include <algorithm>
#include <set>

#include "rtcl/render/instanced_scene.hpp"
#include "rtcl/render/render_layouts.hpp"
#include "rtcl/scene/orthonormal_basis.hpp"

namespace rtcl {

namespace {

void store(float* out, const glm::vec3& v) {
  out[0] = v.x;
  out[1] = v.y;
  out[2] = v.z;
}

DeviceMaterial pack(const Material& m) {
  DeviceMaterial d{};
  store(d.ambient, m.ambient);
  store(d.diffuse, m.diffuse);
  store(d.specular, m.specular);
  store(d.emission, m.emission);
  store(d.kr, m.kr);
  store(d.kt, m.kt);
  d.shininess = m.shininess;
  d.ior = m.ior;
  d.roughness = m.roughness;
  return d;
}

std::uint32_t shape_code(LightShape shape) {
  switch (shape) {
    case LightShape::quad: return RTCL_LIGHT_QUAD;
    case LightShape::disc: return RTCL_LIGHT_DISC;
    case LightShape::sphere: return RTCL_LIGHT_SPHERE;
    case LightShape::triangle: return RTCL_LIGHT_TRIANGLE;
    case LightShape::emissive:  // expanded into triangles before upload
    case LightShape::point: break;
  }
  return RTCL_LIGHT_POINT;
}

// The device form of a light (render_layouts.h): a quad by a corner and its
// edges, a disc by its centre and two radius vectors in its plane.
DeviceLight pack(const Light& l) {
  DeviceLight d{};
  glm::dvec3 position(l.position);
  if (l.shape == LightShape::quad) position -= 0.5 * (glm::dvec3(l.edge1) + glm::dvec3(l.edge2));
  store(d.position, glm::vec3(position));
  store(d.radiance, l.color * l.intensity);
  d.shape = shape_code(l.shape);
  if (l.shape == LightShape::quad || l.shape == LightShape::triangle) {
    store(d.u, l.edge1);
    store(d.v, l.edge2);
  }
  if (l.shape == LightShape::disc) {
    glm::dvec3 n = glm::normalize(glm::dvec3(l.normal)), t1, t2;
    orthonormal_basis(n, t1, t2);
    store(d.u, glm::vec3(t1 * double(l.radius)));
    store(d.v, glm::vec3(t2 * double(l.radius)));
  }
  if (l.shape == LightShape::sphere) d.radius = l.radius;
  return d;
}

}  // namespace

std::vector<std::string> shade_defines(const SceneDescription& scene, const FlatScene& flat) {
  return shade_defines(scene, std::set<std::uint32_t>(flat.material.begin(), flat.material.end()),
                       !flat.geometry.spheres.empty());
}

std::vector<std::string> shade_defines(const SceneDescription& scene, const std::set<std::uint32_t>& used, bool spheres) {
  bool reflection = false, refraction = false, glossy = false, area = false;
  for (std::uint32_t m : used) {
    reflection = reflection || scene.materials[m].reflective() || scene.materials[m].transmissive();
    refraction = refraction || scene.materials[m].transmissive();
    glossy = glossy || scene.materials[m].glossy();
  }
  for (const Light& l : scene.lights) area = area || l.area();
  std::vector<std::string> defines{"RTCL_LIGHT_COUNT=" + std::to_string(scene.lights.size())};
  if (spheres) defines.push_back("RTCL_HAS_SPHERES");
  if (reflection) defines.push_back("RTCL_HAS_REFLECTION");
  if (refraction) defines.push_back("RTCL_HAS_REFRACTION");
  if (glossy) defines.push_back("RTCL_HAS_GLOSSY");
  if (area) defines.push_back("RTCL_HAS_AREA_LIGHTS");
  return defines;
}

std::vector<std::string> generate_defines(const SceneDescription& scene) {
  if (scene.camera.aperture > 0.0f) return {"RTCL_HAS_LENS"};
  return {};
}

namespace {

struct ShadeRecords {
  std::vector<ShadeTriangle> triangles;  // at least one (a placeholder)
  std::vector<ShadeSphere> spheres;      // at least one
};

ShadeRecords shade_records(const FlatScene& flat) {
  const Geometry& g = flat.geometry;
  ShadeRecords r;
  r.triangles.resize(std::max<std::size_t>(g.triangles.size(), 1));
  for (std::size_t t = 0; t < g.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) store(r.triangles[t].v[k], g.vertices[g.triangles[t][k]]);
    r.triangles[t].material = flat.material[t];
  }
  r.spheres.resize(std::max<std::size_t>(g.spheres.size(), 1));
  for (std::size_t s = 0; s < g.spheres.size(); ++s) {
    store(r.spheres[s].center, g.spheres[s].center);
    r.spheres[s].radius = g.spheres[s].radius;
    r.spheres[s].material = flat.material[g.triangles.size() + s];
  }
  return r;
}

// Materials and lights of the scene on the device.
void upload_materials_and_lights(const Device& device, const SceneDescription& scene, DeviceScene& d) {
  std::vector<DeviceMaterial> materials;
  for (const Material& m : scene.materials) materials.push_back(pack(m));
  if (materials.empty()) materials.emplace_back();
  std::vector<DeviceLight> lights(std::max<std::size_t>(scene.lights.size(), 1));
  for (std::size_t l = 0; l < scene.lights.size(); ++l) lights[l] = pack(scene.lights[l]);
  d.materials = device.upload(materials.data(), materials.size() * sizeof(DeviceMaterial), "materials");
  d.lights = device.upload(lights.data(), lights.size() * sizeof(DeviceLight), "lights");
}

}  // namespace

DeviceScene upload_scene(const Device& device, const SceneDescription& scene, const FlatScene& flat, const FlatScene* close) {
  const Geometry& g = flat.geometry;
  ShadeRecords records = shade_records(flat);
  DeviceScene d;
  d.triangles = device.upload(records.triangles.data(), records.triangles.size() * sizeof(ShadeTriangle), "shading triangles");
  d.spheres = device.upload(records.spheres.data(), records.spheres.size() * sizeof(ShadeSphere), "shading spheres");
  upload_materials_and_lights(device, scene, d);
  d.triangle_count = static_cast<std::uint32_t>(g.triangles.size());
  d.sphere_count = static_cast<std::uint32_t>(g.spheres.size());
  d.light_count = static_cast<std::uint32_t>(scene.lights.size());
  d.defines = shade_defines(scene, flat);
  d.generate_defines = generate_defines(scene);
  if (close) {
    ShadeRecords end = shade_records(*close);
    d.triangles_close = device.upload(end.triangles.data(), end.triangles.size() * sizeof(ShadeTriangle), "shading triangles at shutter close");
    d.spheres_close = device.upload(end.spheres.data(), end.spheres.size() * sizeof(ShadeSphere), "shading spheres at shutter close");
    d.defines.push_back("RTCL_HAS_MOTION");
  }
  return d;
}

DeviceScene upload_instanced_scene(const Device& device, const SceneDescription& scene, const InstancedScene& instanced) {
  DeviceScene d;
  d.triangles = instanced.triangles();
  d.spheres = instanced.spheres();
  upload_materials_and_lights(device, scene, d);
  d.light_count = static_cast<std::uint32_t>(scene.lights.size());
  const std::vector<std::uint32_t>& used = instanced.used_materials();
  d.defines = shade_defines(scene, std::set<std::uint32_t>(used.begin(), used.end()), instanced.has_spheres());
  d.defines.push_back("RTCL_HAS_INSTANCES");
  if (instanced.moving()) d.defines.push_back("RTCL_HAS_MOVING_INSTANCES");
  d.generate_defines = generate_defines(scene);
  return d;
}

}  // namespace rtcl
