#include "mesh_scene.hpp"

#include <algorithm>
#include <utility>

#include "rtcl/accel_options.hpp"
#include "rtcl/error.hpp"
#include "rtcl/precision.hpp"
#include "rtcl/scene/two_level.hpp"

namespace rtcl::python {

namespace {

// The structures rtcl::Scene takes as a mesh's bottom level.
bool bvh_family(const std::string& accel) {
  const std::string name = parse_accel_spec(accel).name;
  return name == "bvh" || name == "bvh-ploc" || name == "bvh-packet";
}

glm::vec3 unit_normal(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const glm::dvec3 v0(a), v1(b), v2(c);
  const glm::dvec3 n = glm::cross(v1 - v0, v2 - v0);
  const double length = glm::length(n);
  return length > 0.0 ? glm::vec3(n / length) : glm::vec3(0.0f);
}

// A mesh with its normals and whether it has something to hit. Throws the
// library's Error (naming `call`) for a NaN or infinite coordinate or an
// index out of range.
std::shared_ptr<const Mesh> make_mesh(std::vector<glm::vec3> vertices, std::vector<glm::uvec3> triangles,
                                      const char* call) {
  auto mesh = std::make_shared<Mesh>();
  Geometry view;
  view.source = call;
  view.vertices = std::move(vertices);
  view.triangles = std::move(triangles);
  // A mesh of zero-area triangles only is accepted (nothing of it can be
  // hit), as an empty one is.
  if (!view.triangles.empty()) validate(view, ZeroAreaTest::by_caller);
  mesh->normals.resize(view.triangles.size());
  for (std::size_t i = 0; i < view.triangles.size(); ++i) {
    const glm::uvec3& t = view.triangles[i];
    mesh->normals[i] = unit_normal(view.vertices[t.x], view.vertices[t.y], view.vertices[t.z]);
    if (!mesh->hittable && !zero_area(view, i)) mesh->hittable = true;
  }
  mesh->vertices = std::move(view.vertices);
  mesh->triangles = std::move(view.triangles);
  return mesh;
}

Placement placement_of(std::uint32_t geometry, std::uint32_t instance, const Transform& t) {
  Placement p;
  p.geometry = geometry;
  p.instance = instance;
  p.transform = t;
  p.identity = t == Transform::identity();
  glm::dmat3 a;  // column-major: a[col][row]
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) a[col][row] = t.m[row][col];
  p.cofactor = glm::mat3(glm::determinant(a) * glm::transpose(glm::inverse(a)));
  return p;
}

glm::vec3 apply(const Transform& t, const glm::vec3& v) {
  glm::vec3 out;
  for (int row = 0; row < 3; ++row)
    out[row] = static_cast<float>(double(t.m[row][0]) * v.x + double(t.m[row][1]) * v.y +
                                  double(t.m[row][2]) * v.z + double(t.m[row][3]));
  return out;
}

// One Geometry of every placement's mesh, placed, under `accel`.
std::shared_ptr<const FlatScene> flatten(const std::vector<Placement>& placements,
                                         const std::vector<std::shared_ptr<const Mesh>>& meshes, const Device& device,
                                         const std::string& accel, const AccelConfig& config) {
  auto flat = std::make_shared<FlatScene>();
  Geometry& g = flat->geometry;
  g.source = "RaycastingScene";
  std::size_t vertex_count = 0, triangle_count = 0;
  bool hittable = false;
  for (const Placement& p : placements) {
    vertex_count += meshes[p.geometry]->vertices.size();
    triangle_count += meshes[p.geometry]->triangles.size();
    hittable = hittable || meshes[p.geometry]->hittable;
  }
  if (triangle_count > 0x7fffffffu)
    throw Error("RaycastingScene: the placed meshes hold " + std::to_string(triangle_count) +
                " triangles, more than 2^31-1 in one structure");
  g.vertices.reserve(vertex_count);
  g.triangles.reserve(triangle_count);
  flat->first_prim.reserve(placements.size() + 1);
  flat->normals.reserve(triangle_count);
  for (const Placement& p : placements) {
    const Mesh& m = *meshes[p.geometry];
    flat->first_prim.push_back(static_cast<std::uint32_t>(g.triangles.size()));
    const auto base = static_cast<std::uint32_t>(g.vertices.size());
    if (p.identity) {
      g.vertices.insert(g.vertices.end(), m.vertices.begin(), m.vertices.end());
      flat->normals.insert(flat->normals.end(), m.normals.begin(), m.normals.end());
    } else {
      for (const glm::vec3& v : m.vertices) g.vertices.push_back(apply(p.transform, v));
      for (const glm::uvec3& t : m.triangles)
        flat->normals.push_back(unit_normal(g.vertices[base + t.x], g.vertices[base + t.y], g.vertices[base + t.z]));
    }
    for (const glm::uvec3& t : m.triangles) g.triangles.push_back(t + glm::uvec3(base));
  }
  flat->first_prim.push_back(static_cast<std::uint32_t>(g.triangles.size()));
  // A transform can round a tiny triangle to zero area: make_accel's build
  // skips those, and a scene of only such triangles has nothing to hit.
  if (hittable) {
    hittable = false;
    for (std::size_t i = 0; i < g.triangles.size() && !hittable; ++i) hittable = !zero_area(g, i);
  }
  if (hittable) flat->accel = make_accel(device, accel, g, config);
  return flat;
}

}  // namespace

void FlatScene::locate(std::int32_t prim, std::uint32_t& placement, std::uint32_t& primitive) const {
  const auto p = static_cast<std::uint32_t>(prim);
  // The last part whose first primitive is <= p (parts without triangles
  // share their first primitive with the next one and are never found).
  const auto next = std::upper_bound(first_prim.begin(), first_prim.end() - 1, p);
  placement = static_cast<std::uint32_t>(next - first_prim.begin() - 1);
  primitive = p - first_prim[placement];
}

std::shared_ptr<const FlatScene> BuiltScene::flattened(const Device& device, const std::string& accel,
                                                       const AccelConfig& config) const {
  if (flat) return flat;
  std::lock_guard lock(flatten_mutex_);
  if (!flattened_) flattened_ = flatten(placements, meshes, device, accel, config);
  return flattened_;
}

MeshScene::MeshScene(Device device, std::string accel, AccelConfig config)
    : device_(std::move(device)), accel_(std::move(accel)), config_(std::move(config)) {
  parse_accel_spec(accel_);  // Error: accel "NAME": ...
  require_precision(device_.info(), config_.precision);
}

MeshScene::~MeshScene() = default;

std::uint32_t MeshScene::add_triangles(std::vector<glm::vec3> vertices, std::vector<glm::uvec3> triangles) {
  std::shared_ptr<const Mesh> mesh = make_mesh(std::move(vertices), std::move(triangles), "add_triangles");
  std::lock_guard lock(mutex_);
  std::size_t prims = mesh->triangles.size();
  for (const GeometryEntry& g : geometries_) prims += g.mesh->triangles.size();
  if (geometries_.size() >= kInvalidId - 1 || prims > 0x7fffffffu)
    throw Error("add_triangles: the scene would hold more than 2^31-1 triangles or 2^32-2 meshes");
  const auto id = static_cast<std::uint32_t>(geometries_.size());
  const auto placement = static_cast<std::uint32_t>(placements_.size());
  GeometryEntry entry{mesh, std::nullopt, {placement}};
  std::vector<std::optional<InstanceId>> scene_instances;
  if (scene_) add_to_scene(*scene_, id, entry, *mesh, entry.scene_mesh, scene_instances);
  // Nothing below throws but allocation.
  placements_.push_back({placement_of(id, kInvalidId, Transform::identity()),
                         scene_instances.empty() ? std::nullopt : scene_instances[0]});
  geometries_.push_back(std::move(entry));
  geometry_count_.store(geometries_.size());
  built_.reset();
  return id;
}

void MeshScene::add_to_scene(Scene& scene, std::uint32_t id, const GeometryEntry& g, const Mesh& mesh,
                             std::optional<MeshId>& mesh_id, std::vector<std::optional<InstanceId>>& instances) const {
  instances.assign(g.placements.size(), std::nullopt);
  if (!mesh.hittable) return;
  Geometry geometry;
  geometry.source = "geometry " + std::to_string(id);
  geometry.vertices = mesh.vertices;
  geometry.triangles = mesh.triangles;
  MeshOptions options;
  options.structure = accel_;
  options.options = config_.options;
  mesh_id = scene.add_mesh(geometry, options);
  for (std::size_t k = 0; k < g.placements.size(); ++k) {
    const std::uint32_t p = g.placements[k];
    const Transform& t = p < placements_.size() ? placements_[p].placement.transform : Transform::identity();
    instances[k] = scene.add_instance(Instance{*mesh_id, t, std::nullopt, p});
  }
}

std::unique_ptr<Scene> MeshScene::make_scene(const char* call) const {
  if (!bvh_family(accel_))
    throw Error(std::string(call) + ": instances and vertex updates need a structure of the BVH family (bvh, "
                "bvh-ploc, bvh-packet); this scene's accel is \"" + accel_ + "\"");
  SceneConfig config;
  config.precision = config_.precision;
  config.scattered_sort = config_.scattered_sort;
  return std::make_unique<Scene>(device_, config);
}

MeshScene::FreshScene MeshScene::fresh_scene(const char* call, const Mesh* replacement, std::uint32_t replaced) const {
  FreshScene fresh;
  fresh.scene = make_scene(call);
  fresh.meshes.resize(geometries_.size());
  fresh.instances.resize(geometries_.size());
  for (std::size_t g = 0; g < geometries_.size(); ++g) {
    const Mesh& mesh = replacement && g == replaced ? *replacement : *geometries_[g].mesh;
    add_to_scene(*fresh.scene, static_cast<std::uint32_t>(g), geometries_[g], mesh, fresh.meshes[g], fresh.instances[g]);
  }
  return fresh;
}

void MeshScene::adopt(FreshScene&& fresh) {
  for (std::size_t g = 0; g < geometries_.size(); ++g) {
    geometries_[g].scene_mesh = fresh.meshes[g];
    for (std::size_t k = 0; k < geometries_[g].placements.size(); ++k)
      placements_[geometries_[g].placements[k]].scene_instance = fresh.instances[g][k];
  }
  scene_ = std::move(fresh.scene);
}

void MeshScene::check_geometry(const char* call, std::uint32_t geometry) const {
  if (geometry >= geometries_.size())
    throw Error(std::string(call) + ": geometry_id " + std::to_string(geometry) + " does not exist (" +
                (geometries_.empty() ? std::string("no geometry added yet")
                                     : "geometry ids 0 to " + std::to_string(geometries_.size() - 1)) + ")");
}

std::uint32_t MeshScene::add_instance(std::uint32_t geometry, const Transform& transform) {
  const char* call = "add_instance";
  if (const std::string problem = transform_problem(transform); !problem.empty())
    throw Error(std::string(call) + ": " + problem);
  std::lock_guard lock(mutex_);
  check_geometry(call, geometry);
  if (instance_placement_.size() >= 0x7fffffffu || placements_.size() >= kInvalidId - 1)
    throw Error(std::string(call) + ": the scene holds the most instances it can (2^31-1)");
  const auto instance = static_cast<std::uint32_t>(instance_placement_.size());
  const auto placement = static_cast<std::uint32_t>(placements_.size());
  // The scene, its meshes and the new instance: made aside, kept when
  // every step succeeded.
  FreshScene fresh;
  if (!scene_) fresh = fresh_scene(call);
  Scene& scene = scene_ ? *scene_ : *fresh.scene;
  const std::optional<MeshId> mesh = scene_ ? geometries_[geometry].scene_mesh : fresh.meshes[geometry];
  std::optional<InstanceId> added;
  if (mesh) added = scene.add_instance(Instance{*mesh, transform, std::nullopt, placement});
  // Nothing below throws but allocation.
  if (fresh.scene) adopt(std::move(fresh));
  placements_.push_back({placement_of(geometry, instance, transform), added});
  geometries_[geometry].placements.push_back(placement);
  instance_placement_.push_back(placement);
  instance_count_.store(instance_placement_.size());
  instanced_.store(true);
  built_.reset();
  return instance;
}

void MeshScene::set_transform(std::uint32_t instance, const Transform& transform) {
  const char* call = "set_transform";
  if (const std::string problem = transform_problem(transform); !problem.empty())
    throw Error(std::string(call) + ": " + problem);
  std::lock_guard lock(mutex_);
  if (instance >= instance_placement_.size())
    throw Error(std::string(call) + ": instance_id " + std::to_string(instance) + " does not exist (" +
                (instance_placement_.empty() ? std::string("no instance added yet")
                                             : "instance ids 0 to " + std::to_string(instance_placement_.size() - 1)) +
                ")");
  PlacementEntry& entry = placements_[instance_placement_[instance]];
  if (entry.scene_instance) scene_->set_transform(*entry.scene_instance, transform);
  entry.placement = placement_of(entry.placement.geometry, instance, transform);
  built_.reset();
}

void MeshScene::update_vertices(std::uint32_t geometry, std::vector<glm::vec3> vertices) {
  const char* call = "update_vertices";
  std::lock_guard lock(mutex_);
  check_geometry(call, geometry);
  GeometryEntry& entry = geometries_[geometry];
  if (vertices.size() != entry.mesh->vertices.size())
    throw Error(std::string(call) + ": vertex_positions has " + std::to_string(vertices.size()) +
                " vertices; geometry " + std::to_string(geometry) + " has " +
                std::to_string(entry.mesh->vertices.size()));
  std::vector<glm::uvec3> triangles = entry.mesh->triangles;
  std::shared_ptr<const Mesh> mesh = make_mesh(std::move(vertices), std::move(triangles), call);
  if (entry.mesh->hittable && !mesh->hittable)
    throw Error(std::string(call) + ": vertex_positions leave every triangle of geometry " + std::to_string(geometry) +
                " with zero area (nothing to hit)");
  FreshScene fresh;
  if (!scene_) {
    fresh = fresh_scene(call, mesh.get(), geometry);
  } else if (entry.scene_mesh) {
    std::vector<float> xyz(3 * mesh->vertices.size());
    for (std::size_t v = 0; v < mesh->vertices.size(); ++v)
      for (int k = 0; k < 3; ++k) xyz[3 * v + k] = mesh->vertices[v][k];
    scene_->update_vertices(*entry.scene_mesh, xyz);
  } else if (mesh->hittable) {
    // A mesh that had nothing to hit now has: into the scene with its placements.
    std::optional<MeshId> mesh_id;
    std::vector<std::optional<InstanceId>> instance_ids;
    add_to_scene(*scene_, geometry, entry, *mesh, mesh_id, instance_ids);
    entry.scene_mesh = mesh_id;
    for (std::size_t k = 0; k < entry.placements.size(); ++k)
      placements_[entry.placements[k]].scene_instance = instance_ids[k];
  }
  if (fresh.scene) adopt(std::move(fresh));
  entry.mesh = std::move(mesh);
  instanced_.store(true);
  built_.reset();
}

SceneView MeshScene::snapshot() const {
  std::unique_lock lock(mutex_);
  if (!built_) {
    auto built = std::make_shared<BuiltScene>();
    built->placements.reserve(placements_.size());
    for (const PlacementEntry& p : placements_) built->placements.push_back(p.placement);
    built->meshes.reserve(geometries_.size());
    for (const GeometryEntry& g : geometries_) {
      built->meshes.push_back(g.mesh);
      built->hittable = built->hittable || g.mesh->hittable;
    }
    if (scene_) {
      // Waits for the queries in flight on the previous commit.
      std::unique_lock commit(commit_mutex_);
      scene_->commit();
      built->scene = scene_.get();
    } else {
      built->flat = flatten(built->placements, built->meshes, device_, accel_, config_);
      built->hittable = built->flat->accel != nullptr;
    }
    built_ = std::move(built);
  }
  // Taken while mutex_ is held, so that no commit comes between.
  SceneView view{built_, scene_ ? std::shared_lock(commit_mutex_) : std::shared_lock<std::shared_mutex>()};
  return view;
}

}  // namespace rtcl::python
