#include "mesh_scene.hpp"

#include <algorithm>
#include <utility>

#include "rtcl/accel_options.hpp"
#include "rtcl/error.hpp"
#include "rtcl/precision.hpp"

namespace rtcl::python {

void BuiltScene::locate(std::int32_t prim, std::uint32_t& geometry_id, std::uint32_t& primitive_id) const {
  const auto p = static_cast<std::uint32_t>(prim);
  // The last mesh whose first primitive is <= p (meshes without triangles
  // share their first primitive with the next one and are never found).
  const auto next = std::upper_bound(first_prim.begin(), first_prim.end() - 1, p);
  geometry_id = static_cast<std::uint32_t>(next - first_prim.begin() - 1);
  primitive_id = p - first_prim[geometry_id];
}

MeshScene::MeshScene(Device device, std::string accel, AccelConfig config)
    : device_(std::move(device)), accel_(std::move(accel)), config_(std::move(config)) {
  parse_accel_spec(accel_);  // Error: accel "NAME": ...
  require_precision(device_.info(), config_.precision);
}

std::uint32_t MeshScene::add_triangles(std::vector<glm::vec3> vertices, std::vector<glm::uvec3> triangles) {
  auto mesh = std::make_shared<Mesh>();
  mesh->vertices = std::move(vertices);
  mesh->triangles = std::move(triangles);
  if (!mesh->triangles.empty()) {
    // The library's checks, on this mesh alone: the scene is unchanged when
    // they fail. A mesh of zero-area triangles only is accepted (nothing of
    // it can be hit), as an empty one is.
    Geometry view;
    view.source = "add_triangles";
    view.vertices = std::move(mesh->vertices);
    view.triangles = std::move(mesh->triangles);
    validate(view, ZeroAreaTest::by_caller);
    mesh->vertices = std::move(view.vertices);
    mesh->triangles = std::move(view.triangles);
  }
  std::lock_guard lock(mutex_);
  const std::size_t prims = [&] {
    std::size_t n = 0;
    for (const auto& m : meshes_) n += m->triangles.size();
    return n;
  }();
  if (meshes_.size() >= kInvalidId - 1 || prims + mesh->triangles.size() > 0x7fffffffu)
    throw Error("add_triangles: the scene would hold more than 2^31-1 triangles or 2^32-2 meshes");
  meshes_.push_back(std::move(mesh));
  geometry_count_.store(meshes_.size());
  built_.reset();
  return static_cast<std::uint32_t>(meshes_.size() - 1);
}

std::shared_ptr<const BuiltScene> MeshScene::snapshot() const {
  std::lock_guard lock(mutex_);
  if (built_) return built_;
  auto built = std::make_shared<BuiltScene>();
  Geometry& g = built->geometry;
  g.source = "RaycastingScene";
  std::size_t vertex_count = 0, triangle_count = 0;
  for (const auto& m : meshes_) {
    vertex_count += m->vertices.size();
    triangle_count += m->triangles.size();
  }
  g.vertices.reserve(vertex_count);
  g.triangles.reserve(triangle_count);
  built->first_prim.reserve(meshes_.size() + 1);
  for (const auto& m : meshes_) {
    built->first_prim.push_back(static_cast<std::uint32_t>(g.triangles.size()));
    const auto base = static_cast<std::uint32_t>(g.vertices.size());
    g.vertices.insert(g.vertices.end(), m->vertices.begin(), m->vertices.end());
    for (const glm::uvec3& t : m->triangles) g.triangles.push_back(t + glm::uvec3(base));
  }
  built->first_prim.push_back(static_cast<std::uint32_t>(g.triangles.size()));
  built->normals.resize(g.triangles.size());
  bool hittable = false;
  for (std::size_t i = 0; i < g.triangles.size(); ++i) {
    const glm::uvec3& t = g.triangles[i];
    const glm::dvec3 v0(g.vertices[t.x]), v1(g.vertices[t.y]), v2(g.vertices[t.z]);
    const glm::dvec3 n = glm::cross(v1 - v0, v2 - v0);
    const double length = glm::length(n);
    built->normals[i] = length > 0.0 ? glm::vec3(n / length) : glm::vec3(0.0f);
    if (!hittable && !zero_area(g, i)) hittable = true;
  }
  if (hittable) built->accel = make_accel(device_, accel_, g, config_);
  built_ = std::move(built);
  return built_;
}

}  // namespace rtcl::python
