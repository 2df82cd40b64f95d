#include "rtcl/render/instanced_scene.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <string>

#include "rtcl/accel_options.hpp"
#include "rtcl/error.hpp"
#include "rtcl/scene/motion.hpp"

namespace rtcl {

namespace {

// glm's column-major dmat4 as the 3x4 rows of a Transform, rounded to float.
Transform to_transform(const glm::dmat4& m) {
  Transform t;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) t.m[r][c] = static_cast<float>(m[c][r]);
  return t;
}

Transform sphere_transform(const SceneSphere& s) {
  Transform t;
  for (int r = 0; r < 3; ++r) {
    t.m[r] = {0.0f, 0.0f, 0.0f, static_cast<float>(s.center[r])};
    t.m[r][r] = static_cast<float>(s.radius);
  }
  return t;
}

void store_rows(float* out, const Transform& t) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) out[r * 4 + c] = t.m[r][c];
}

void store(float* out, const glm::vec3& v) {
  out[0] = v.x;
  out[1] = v.y;
  out[2] = v.z;
}

bool is_bottom_level_structure(const std::string& name) {
  return name == "bvh" || name == "bvh-ploc" || name == "bvh-packet";
}

}  // namespace

std::vector<Light> instanced_lights(const SceneDescription& scene) {
  if (std::none_of(scene.lights.begin(), scene.lights.end(), [](const Light& l) { return l.shape == LightShape::emissive; }))
    return scene.lights;
  auto emits = [&](std::uint32_t m) { return glm::any(glm::greaterThan(scene.materials[m].emission, glm::vec3(0.0f))); };
  // Only the meshes that emit: the same emitting triangles in the same
  // order as the whole scene's flattening.
  SceneDescription emitters = scene;
  emitters.meshes.clear();
  emitters.spheres.clear();
  for (const SceneMesh& mesh : scene.meshes)
    if (std::any_of(mesh.materials().begin(), mesh.materials().end(), emits)) emitters.meshes.push_back(mesh);
  if (emitters.meshes.empty()) return expand_emissive_lights(scene, FlatScene{});  // throws: nothing emits
  if (!scene_moves(emitters)) return expand_emissive_lights(emitters, flatten(emitters));
  const SceneDescription at_open = scene_at(emitters, scene.camera.shutter_open);
  const SceneDescription at_close = scene_at(emitters, scene.camera.shutter_close);
  std::vector<Light> lights = expand_emissive_lights(at_open, flatten(at_open));
  std::vector<Light> end = expand_emissive_lights(at_close, flatten(at_close));
  for (std::size_t l = 0; l < end.size(); ++l)
    if (end[l].position != lights[l].position || end[l].edge1 != lights[l].edge1 || end[l].edge2 != lights[l].edge2)
      throw Error(scene.source + ": an emitting triangle of a moving mesh lights the scene (lights of type "
                  "emissive must not move)");
  return lights;
}

InstancedScene::InstancedScene(const Device& device, const SceneDescription& scene, std::string_view accel_name,
                               const AccelConfig& config)
    : device_(device), source_(scene) {
  validate(scene);
  const double open = scene.camera.shutter_open, close = scene.camera.shutter_close;
  if (scene_moves(scene)) check_motion(scene, open, close);
  const std::string structure = parse_accel_spec(accel_name).name;
  if (!is_bottom_level_structure(structure))
    throw Error("Renderer accel \"" + std::string(accel_name) + "\": " + scene.source +
                " places one mesh in several objects, which the renderer traces as instances of a structure of "
                "the BVH family (bvh, bvh-ploc, bvh-packet)");
  scene_ = std::make_unique<Scene>(device, SceneConfig{config.precision, config.scattered_sort});
  const MeshOptions options{std::string(accel_name), config.options};

  std::vector<ShadeTriangle> triangles;
  std::vector<ShadeSphere> spheres;
  std::set<std::uint32_t> used;
  auto add_bottom = [&](const Geometry& g, std::vector<std::uint32_t> materials, const std::string& what) {
    Bottom b;
    try {
      b.id = scene_->add_mesh(g, options);
    } catch (const Error& e) {
      throw Error(scene.source + ": " + what + ": " + e.what());
    }
    b.first_triangle = static_cast<std::uint32_t>(triangles.size());
    b.first_sphere = static_cast<std::uint32_t>(spheres.size());
    b.triangle_count = static_cast<std::uint32_t>(g.triangles.size());
    for (std::size_t t = 0; t < g.triangles.size(); ++t) {
      ShadeTriangle r{};
      for (int k = 0; k < 3; ++k) store(r.v[k], g.vertices[g.triangles[t][k]]);
      r.material = materials[t];
      triangles.push_back(r);
    }
    for (std::size_t s = 0; s < g.spheres.size(); ++s) {
      ShadeSphere r{};
      store(r.center, g.spheres[s].center);
      r.radius = g.spheres[s].radius;
      r.material = materials[g.triangles.size() + s];
      spheres.push_back(r);
    }
    used.insert(materials.begin(), materials.end());
    b.materials = std::move(materials);
    bottoms_.push_back(std::move(b));
    return static_cast<std::uint32_t>(bottoms_.size() - 1);
  };

  // Each shape once, in the order of its first mesh.
  std::map<const MeshShape*, std::uint32_t> shape_bottom;
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    const SceneMesh& mesh = scene.meshes[i];
    if (mesh.triangles().empty()) continue;  // nothing to hit, as flatten() adds nothing
    auto [it, added] = shape_bottom.try_emplace(mesh.shape.get(), 0u);
    if (added) {
      Geometry g;
      g.source = mesh.name;
      g.vertices = mesh.vertices();
      g.triangles = mesh.triangles();
      it->second = add_bottom(g, mesh.materials(), "mesh " + mesh.name);
    }
    objects_.push_back(Object{Object::mesh, i, it->second, {}});
  }
  // The still spheres as one mesh in place; each moving sphere an instance
  // of a unit sphere (one mesh per material), scaled by its radius and
  // moved to its centre: the blend of two such transforms moves the centre
  // and the radius linearly, as sphere_at does.
  Geometry still;
  still.source = scene.source + ": spheres";
  std::vector<std::uint32_t> still_materials;
  std::map<std::uint32_t, std::uint32_t> unit_bottom;  // material -> bottom
  std::vector<Object> moving_spheres;
  for (std::size_t i = 0; i < scene.spheres.size(); ++i) {
    const SceneSphere& s = scene.spheres[i];
    if (!s.moving) {
      still.spheres.push_back(Sphere{glm::vec3(s.center), static_cast<float>(s.radius)});
      still_materials.push_back(s.material);
      continue;
    }
    auto [it, added] = unit_bottom.try_emplace(s.material, 0u);
    if (added) {
      Geometry unit;
      unit.source = scene.source + ": moving sphere " + std::to_string(i);
      unit.spheres.push_back(Sphere{glm::vec3(0.0f), 1.0f});
      it->second = add_bottom(unit, {s.material}, "sphere " + std::to_string(i));
    }
    moving_spheres.push_back(Object{Object::moving_sphere, i, it->second, {}});
  }
  if (!still.spheres.empty())
    objects_.push_back(Object{Object::still_spheres, 0, add_bottom(still, still_materials, "spheres"), {}});
  objects_.insert(objects_.end(), moving_spheres.begin(), moving_spheres.end());
  has_spheres_ = !spheres.empty();
  used_materials_.assign(used.begin(), used.end());

  for (std::size_t k = 0; k < objects_.size(); ++k) {
    Object& o = objects_[k];
    Transform at_open, at_close;
    place(o, open, close, at_open, at_close);
    bool moves = o.kind == Object::moving_sphere || (o.kind == Object::mesh && scene.meshes[o.index].end_transform);
    moving_ = moving_ || moves;
    Instance in{bottoms_[o.bottom].id, at_open, std::nullopt, static_cast<std::uint32_t>(k)};
    if (moves) in.at_close = at_close;
    try {
      o.id = scene_->add_instance(in);
    } catch (const Error& e) {
      std::string what = o.kind == Object::mesh ? "mesh " + scene.meshes[o.index].name
                                                : "sphere " + std::to_string(o.index);
      throw Error(scene.source + ": " + what + ": " + e.what());
    }
    records_.push_back(record(o, at_open, moves ? at_close : at_open));
  }
  scene_->commit();

  if (triangles.empty()) triangles.emplace_back();
  if (spheres.empty()) spheres.emplace_back();
  triangles_ = device.upload(triangles.data(), triangles.size() * sizeof(ShadeTriangle), "shading triangles");
  spheres_ = device.upload(spheres.data(), spheres.size() * sizeof(ShadeSphere), "shading spheres");
  instances_ = device.upload(records_.data(), records_.size() * sizeof(ShadeInstance), "shading instances");
  shading_bytes_ = triangles.size() * sizeof(ShadeTriangle) + spheres.size() * sizeof(ShadeSphere) +
                   records_.size() * sizeof(ShadeInstance);
}

void InstancedScene::place(const Object& o, double open, double close, Transform& at_open, Transform& at_close) const {
  switch (o.kind) {
    case Object::mesh: {
      const SceneMesh& mesh = source_.meshes[o.index];
      at_open = to_transform(transform_at(mesh, open));
      at_close = to_transform(transform_at(mesh, close));
      return;
    }
    case Object::still_spheres:
      at_open = at_close = Transform::identity();
      return;
    case Object::moving_sphere:
      at_open = sphere_transform(sphere_at(source_.spheres[o.index], open));
      at_close = sphere_transform(sphere_at(source_.spheres[o.index], close));
      return;
  }
}

ShadeInstance InstancedScene::record(const Object& o, const Transform& at_open, const Transform& at_close) const {
  const Bottom& b = bottoms_[o.bottom];
  ShadeInstance r{};
  store_rows(r.open, at_open);
  store_rows(r.close, at_close);
  r.first_triangle = b.first_triangle;
  r.first_sphere = b.first_sphere;
  r.triangle_count = b.triangle_count;
  glm::dmat3 a(1.0);
  for (int row = 0; row < 3; ++row)
    for (int c = 0; c < 3; ++c) a[c][row] = at_open.m[row][c];
  r.flags = glm::determinant(a) < 0.0 ? RTCL_SHADE_MIRRORED : 0u;
  return r;
}

CommitStats InstancedScene::set_shutter(double open, double close) {
  SceneDescription shifted = source_;
  shifted.camera.shutter_open = static_cast<float>(open);
  shifted.camera.shutter_close = static_cast<float>(close);
  check_motion(shifted, open, close);  // before any edit: a refusal changes nothing
  std::vector<ShadeInstance> records = records_;
  for (std::size_t k = 0; k < objects_.size(); ++k) {
    const Object& o = objects_[k];
    Instance in = scene_->instance(o.id);
    if (!in.at_close) continue;  // still
    place(o, open, close, in.transform, *in.at_close);
    scene_->set_instance(o.id, in);
    records[k] = record(o, in.transform, *in.at_close);
  }
  CommitStats stats = scene_->commit();
  records_ = std::move(records);
  source_.camera = shifted.camera;
  with_cl_errors([&] {
    device_.queue().enqueueWriteBuffer(instances_, CL_TRUE, 0, records_.size() * sizeof(ShadeInstance), records_.data());
  });
  return stats;
}

std::uint32_t InstancedScene::material(std::uint32_t object, std::int32_t prim) const {
  return bottoms_.at(objects_.at(object).bottom).materials.at(static_cast<std::size_t>(prim));
}

}  // namespace rtcl
