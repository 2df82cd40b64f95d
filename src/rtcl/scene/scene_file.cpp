#include "rtcl/scene/scene_file.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "rtcl/accel_options.hpp"
#include "rtcl/error.hpp"
#include "rtcl/scene/motion.hpp"

namespace rtcl {

namespace {

using nlohmann::json;

// Reads JSON values with errors that name the file and the key path
// ("objects[2].radius").
class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw Error(source_ + ": " + (where.empty() ? "" : where + ": ") + what);
  }

  const json& object(const json& v, const std::string& where, std::initializer_list<const char*> known) const {
    if (!v.is_object()) fail(where, std::string("expected an object, got ") + v.type_name());
    for (const auto& item : v.items()) {
      if (std::find_if(known.begin(), known.end(), [&](const char* k) { return item.key() == k; }) != known.end())
        continue;
      std::string list;
      for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
      fail(join(where, item.key()), "unknown key (known here: " + list + ")");
    }
    return v;
  }

  const json& required(const json& obj, const std::string& where, const char* key) const {
    if (!obj.contains(key)) fail(where, std::string("missing required key '") + key + "'");
    return obj.at(key);
  }

  double number(const json& v, const std::string& where) const {
    if (!v.is_number()) fail(where, std::string("expected a number, got ") + v.type_name());
    return v.get<double>();
  }

  std::string string(const json& v, const std::string& where) const {
    if (!v.is_string()) fail(where, std::string("expected a string, got ") + v.type_name());
    return v.get<std::string>();
  }

  glm::dvec3 vec3(const json& v, const std::string& where) const {
    if (!v.is_array() || v.size() != 3) fail(where, "expected an array of 3 numbers");
    return {number(v[0], where + "[0]"), number(v[1], where + "[1]"), number(v[2], where + "[2]")};
  }

  // A number (grey, or uniform) or an array of 3 numbers.
  glm::dvec3 triple(const json& v, const std::string& where) const {
    if (v.is_number()) return glm::dvec3(v.get<double>());
    if (!v.is_array() || v.size() != 3) fail(where, std::string("expected a number or an array of 3 numbers, got ") + v.type_name());
    return vec3(v, where);
  }

  static std::string join(const std::string& where, const std::string& key) {
    return where.empty() ? key : where + "." + key;
  }
  static std::string index(const std::string& where, std::size_t i) { return where + "[" + std::to_string(i) + "]"; }

  const std::string& source() const { return source_; }

 private:
  std::string source_;
};

// Rejects duplicate keys in any object (nlohmann keeps the last silently).
json parse_strict(const std::string& text, const Reader& r) {
  std::vector<std::set<std::string>> open_objects;
  json::parser_callback_t check = [&](int, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start) open_objects.emplace_back();
    else if (event == json::parse_event_t::object_end) open_objects.pop_back();
    else if (event == json::parse_event_t::key && !open_objects.back().insert(parsed.get<std::string>()).second)
      r.fail("", "duplicate key '" + parsed.get<std::string>() + "'");
    return true;
  };
  try {
    return json::parse(text, check, /*allow_exceptions=*/true, /*ignore_comments=*/true);
  } catch (const json::exception& e) {  // parse_error, and out_of_range for a number beyond double
    std::string what = e.what();
    if (auto p = what.find("] "); what.rfind("[json.exception", 0) == 0 && p != std::string::npos)
      what = what.substr(p + 2);
    r.fail("", "malformed JSON: " + what);
  }
}

glm::vec3 to_float(const glm::dvec3& v) { return glm::vec3(v); }

// scale, then rotate (degrees about x, then y, then z), then translate.
glm::dmat4 read_transform(const Reader& r, const json& v, const std::string& where) {
  r.object(v, where, {"scale", "rotate", "translate"});
  glm::dvec3 scale(1.0), rotate(0.0), translate(0.0);
  if (v.contains("scale")) scale = r.triple(v["scale"], Reader::join(where, "scale"));
  if (v.contains("rotate")) rotate = r.vec3(v["rotate"], Reader::join(where, "rotate"));
  if (v.contains("translate")) translate = r.vec3(v["translate"], Reader::join(where, "translate"));
  if (scale.x == 0.0 || scale.y == 0.0 || scale.z == 0.0) r.fail(Reader::join(where, "scale"), "must not be zero");
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), translate);
  m = glm::rotate(m, glm::radians(rotate.z), glm::dvec3(0, 0, 1));
  m = glm::rotate(m, glm::radians(rotate.y), glm::dvec3(0, 1, 0));
  m = glm::rotate(m, glm::radians(rotate.x), glm::dvec3(1, 0, 0));
  return glm::scale(m, scale);
}

Camera read_camera(const Reader& r, const json& v) {
  const std::string where = "camera";
  r.object(v, where, {"position", "look_at", "up", "fov", "aspect", "aperture", "focus_distance", "shutter"});
  Camera c;
  c.position = to_float(r.vec3(r.required(v, where, "position"), "camera.position"));
  c.look_at = to_float(r.vec3(r.required(v, where, "look_at"), "camera.look_at"));
  if (v.contains("up")) c.up = to_float(r.vec3(v["up"], "camera.up"));
  if (v.contains("fov")) c.fov_deg = static_cast<float>(r.number(v["fov"], "camera.fov"));
  if (v.contains("aspect")) {
    c.aspect = static_cast<float>(r.number(v["aspect"], "camera.aspect"));
    if (!(c.aspect > 0.0f)) r.fail("camera.aspect", "must be positive");
  }
  if (!(c.fov_deg > 0.0f && c.fov_deg < 180.0f)) r.fail("camera.fov", "must lie in (0, 180) degrees");
  if (v.contains("aperture")) {
    double a = r.number(v["aperture"], "camera.aperture");
    if (!(a >= 0.0)) r.fail("camera.aperture", "the lens radius must not be negative (0: pinhole), got " + v["aperture"].dump());
    c.aperture = static_cast<float>(a);
  }
  if (v.contains("focus_distance")) {
    double f = r.number(v["focus_distance"], "camera.focus_distance");
    if (!(f > 0.0)) r.fail("camera.focus_distance", "must be positive, got " + v["focus_distance"].dump());
    c.focus_distance = static_cast<float>(f);
  }
  if (v.contains("shutter")) {
    const json& s = v["shutter"];
    if (!s.is_array() || s.size() != 2) r.fail("camera.shutter", "expected [open, close] (keyframe times)");
    double open = r.number(s[0], "camera.shutter[0]"), close = r.number(s[1], "camera.shutter[1]");
    if (!std::isfinite(open) || !std::isfinite(close) || open > close)
      r.fail("camera.shutter", "must be finite with open <= close, got " + s.dump());
    c.shutter_open = static_cast<float>(open);
    c.shutter_close = static_cast<float>(close);
  }
  return c;
}

Light read_light(const Reader& r, const json& v, const std::string& where) {
  r.object(v, where, {"type", "position", "color", "intensity", "edge1", "edge2", "normal", "radius"});
  Light l;
  std::string type = v.contains("type") ? r.string(v["type"], Reader::join(where, "type")) : "point";
  if (type == "point") l.shape = LightShape::point;
  else if (type == "quad") l.shape = LightShape::quad;
  else if (type == "disc") l.shape = LightShape::disc;
  else if (type == "sphere") l.shape = LightShape::sphere;
  else if (type == "emissive") l.shape = LightShape::emissive;
  else r.fail(Reader::join(where, "type"), "unknown light type '" + type + "' (known: point, quad, disc, sphere, emissive)");
  // The keys each shape takes (beyond position, color, intensity, type).
  auto allow = [&](const char* key, bool allowed) {
    if (v.contains(key) && !allowed) r.fail(Reader::join(where, key), "not a key of " + std::string(type == "emissive" ? "an " : "a ") + type + " light");
  };
  allow("edge1", l.shape == LightShape::quad);
  allow("edge2", l.shape == LightShape::quad);
  allow("normal", l.shape == LightShape::disc);
  allow("radius", l.shape == LightShape::disc || l.shape == LightShape::sphere);
  allow("position", l.shape != LightShape::emissive);
  if (l.shape == LightShape::quad) {
    l.edge1 = to_float(r.vec3(r.required(v, where, "edge1"), Reader::join(where, "edge1")));
    l.edge2 = to_float(r.vec3(r.required(v, where, "edge2"), Reader::join(where, "edge2")));
  }
  if (l.shape == LightShape::disc) {
    glm::dvec3 n = r.vec3(r.required(v, where, "normal"), Reader::join(where, "normal"));
    if (glm::length(n) == 0.0) r.fail(Reader::join(where, "normal"), "must not be zero");
    l.normal = to_float(n);
  }
  if (l.shape == LightShape::disc || l.shape == LightShape::sphere) {
    double radius = r.number(r.required(v, where, "radius"), Reader::join(where, "radius"));
    if (!(radius >= 0.0)) r.fail(Reader::join(where, "radius"), "must not be negative (0: a point light), got " + v["radius"].dump());
    l.radius = static_cast<float>(radius);
  }
  if (l.shape != LightShape::emissive)
    l.position = to_float(r.vec3(r.required(v, where, "position"), Reader::join(where, "position")));
  if (v.contains("color")) l.color = to_float(r.triple(v["color"], Reader::join(where, "color")));
  if (v.contains("intensity")) l.intensity = static_cast<float>(r.number(v["intensity"], Reader::join(where, "intensity")));
  if (l.intensity < 0.0f) r.fail(Reader::join(where, "intensity"), "must not be negative");
  return l;
}

Material read_material(const Reader& r, const json& v, const std::string& name, const std::string& where) {
  r.object(v, where, {"ambient", "diffuse", "specular", "shininess", "emission", "kr", "kt", "ior", "roughness"});
  Material m;
  m.name = name;
  auto colour = [&](const char* key, glm::vec3& out, bool unit) {
    if (!v.contains(key)) return;
    std::string at = Reader::join(where, key);
    glm::dvec3 c = r.triple(v[key], at);
    if (c.x < 0.0 || c.y < 0.0 || c.z < 0.0) r.fail(at, "must not be negative");
    if (unit && (c.x > 1.0 || c.y > 1.0 || c.z > 1.0)) r.fail(at, "must lie in [0, 1]");
    out = to_float(c);
  };
  colour("diffuse", m.diffuse, false);
  m.ambient = m.diffuse;  // default: ambient light reflects like diffuse light
  colour("ambient", m.ambient, false);
  colour("specular", m.specular, false);
  colour("emission", m.emission, false);
  colour("kr", m.kr, true);
  colour("kt", m.kt, true);
  if (v.contains("shininess")) {
    m.shininess = static_cast<float>(r.number(v["shininess"], Reader::join(where, "shininess")));
    if (m.shininess < 0.0f) r.fail(Reader::join(where, "shininess"), "must not be negative");
  }
  if (v.contains("ior")) {
    double ior = r.number(v["ior"], Reader::join(where, "ior"));
    if (!(ior > 0.0)) r.fail(Reader::join(where, "ior"), "index of refraction must be positive (got " + v["ior"].dump() + ")");
    m.ior = static_cast<float>(ior);
  }
  if (v.contains("roughness")) {
    double rough = r.number(v["roughness"], Reader::join(where, "roughness"));
    if (!(rough >= 0.0 && rough <= 1.0))
      r.fail(Reader::join(where, "roughness"), "must lie in [0, 1] (0: mirror), got " + v["roughness"].dump());
    m.roughness = static_cast<float>(rough);
  }
  return m;
}
// "accel": a spec string ("grid:lambda=4") or an object {"name": "grid",
// "lambda": 4, "res": [64, 32, 16] or "64x32x16"}; returned as the checked
// spec text (format_accel_spec).
std::string read_accel(const Reader& r, const json& v) {
  const std::string where = r.source() + ": accel";
  if (v.is_string()) return format_accel_spec(parse_accel_spec(v.get<std::string>(), where));
  if (!v.is_object()) r.fail("accel", std::string("expected a string or an object, got ") + v.type_name());
  std::string text = r.string(r.required(v, "accel", "name"), "accel.name");
  char sep = ':';
  for (const auto& item : v.items()) {
    if (item.key() == "name") continue;
    const json& x = item.value();
    std::string value;
    if (x.is_string()) value = x.get<std::string>();
    else if (x.is_boolean() || x.is_number()) value = x.dump();
    else if (x.is_array() && x.size() == 3 && x[0].is_number_integer() && x[1].is_number_integer() &&
             x[2].is_number_integer())
      value = x[0].dump() + "x" + x[1].dump() + "x" + x[2].dump();
    else r.fail("accel." + item.key(), std::string("expected a number, boolean, string or [a, b, c], got ") + x.type_name());
    text += sep + item.key() + "=" + value;
    sep = ',';
  }
  return format_accel_spec(parse_accel_spec(text, where));
}

class SceneBuilder {
 public:
  SceneBuilder(const Reader& r, std::filesystem::path base_dir) : r_(r), base_dir_(std::move(base_dir)) {}

  SceneDescription build(const json& root) {
    r_.object(root, "", {"camera", "ambient", "background", "lights", "materials", "objects", "accel", "precision"});
    scene_.source = r_.source();
    if (root.contains("accel")) scene_.accel = read_accel(r_, root["accel"]);
    scene_.camera = read_camera(r_, r_.required(root, "", "camera"));
    if (root.contains("ambient")) scene_.ambient = colour(root["ambient"], "ambient");
    if (root.contains("background")) scene_.background = colour(root["background"], "background");
    if (root.contains("precision")) {
      std::string level = r_.string(root["precision"], "precision");
      const auto& names = precision_names();
      if (std::find(names.begin(), names.end(), level) == names.end())
        r_.fail("precision", "unknown precision level '" + level + "' (known: fast, robust, exact)");
      scene_.precision = parse_precision(level);
    }
    if (root.contains("lights")) {
      const json& lights = root["lights"];
      if (!lights.is_array()) r_.fail("lights", std::string("expected an array, got ") + lights.type_name());
      for (std::size_t i = 0; i < lights.size(); ++i)
        scene_.lights.push_back(read_light(r_, lights[i], Reader::index("lights", i)));
    }
    if (root.contains("materials")) {
      const json& materials = root["materials"];
      if (!materials.is_object()) r_.fail("materials", std::string("expected an object, got ") + materials.type_name());
      for (const auto& item : materials.items()) {
        named_[item.key()] = static_cast<std::uint32_t>(scene_.materials.size());
        scene_.materials.push_back(read_material(r_, item.value(), item.key(), "materials." + item.key()));
      }
    }
    const json& objects = r_.required(root, "", "objects");
    if (!objects.is_array()) r_.fail("objects", std::string("expected an array, got ") + objects.type_name());
    if (objects.empty()) r_.fail("objects", "the scene needs at least one object");
    for (std::size_t i = 0; i < objects.size(); ++i) read_object(objects[i], Reader::index("objects", i));
    validate(scene_);
    return std::move(scene_);
  }

 private:
  glm::vec3 colour(const json& v, const std::string& where) const {
    glm::dvec3 c = r_.triple(v, where);
    if (c.x < 0.0 || c.y < 0.0 || c.z < 0.0) r_.fail(where, "must not be negative");
    return to_float(c);
  }

  std::uint32_t material_named(const json& v, const std::string& where) const {
    std::string name = r_.string(v, where);
    auto it = named_.find(name);
    if (it == named_.end()) {
      std::string known;
      for (const auto& [k, _] : named_) known += (known.empty() ? "" : ", ") + k;
      r_.fail(where, "unknown material '" + name + "' (defined in \"materials\": " + (known.empty() ? "none" : known) + ")");
    }
    return it->second;
  }

  void read_object(const json& v, const std::string& where) {
    if (!v.is_object()) r_.fail(where, std::string("expected an object, got ") + v.type_name());
    std::string type = r_.string(r_.required(v, where, "type"), Reader::join(where, "type"));
    if (type == "mesh") read_mesh(v, where);
    else if (type == "sphere") read_sphere(v, where);
    else r_.fail(Reader::join(where, "type"), "unknown object type '" + type + "' (known: mesh, sphere)");
  }

  void read_sphere(const json& v, const std::string& where) {
    r_.object(v, where, {"type", "center", "radius", "material", "transform", "motion"});
    SceneSphere s;
    s.center = r_.vec3(r_.required(v, where, "center"), Reader::join(where, "center"));
    s.radius = r_.number(r_.required(v, where, "radius"), Reader::join(where, "radius"));
    if (!(s.radius > 0.0)) r_.fail(Reader::join(where, "radius"), "must be positive");
    s.material = material_named(r_.required(v, where, "material"), Reader::join(where, "material"));
    glm::dmat4 t(1.0);
    if (v.contains("transform")) {
      std::string at = Reader::join(where, "transform");
      t = read_transform(r_, v["transform"], at);
      similarity_scale(t, r_.source() + ": " + at + " (a sphere's scale must be uniform)");
    }
    glm::dvec3 object_center = s.center;
    double object_radius = s.radius;
    s.radius = object_radius * similarity_scale(t, r_.source() + ": " + where);
    s.center = glm::dvec3(t * glm::dvec4(object_center, 1.0));
    if (v.contains("motion")) {
      std::string at = Reader::join(where, "motion");
      glm::dmat4 end = read_transform(r_, v["motion"], at) * t;
      s.moving = true;
      s.motion_key = r_.source() + ": " + at;
      s.end_radius = object_radius * similarity_scale(end, s.motion_key + " (a sphere's scale must stay uniform)");
      s.end_center = glm::dvec3(end * glm::dvec4(object_center, 1.0));
    }
    scene_.spheres.push_back(s);
  }

  void read_mesh(const json& v, const std::string& where) {
    r_.object(v, where, {"type", "file", "material", "materials", "transform", "motion"});
    std::string file_at = Reader::join(where, "file");
    std::string file = r_.string(r_.required(v, where, "file"), file_at);
    std::filesystem::path path = std::filesystem::path(file).is_absolute() ? std::filesystem::path(file) : base_dir_ / file;
    const std::string key = path.lexically_normal().string();
    const LoadedMesh& loaded = load(key, file_at);

    // Per MTL material: the scene material it maps to.
    std::vector<std::uint32_t> map(loaded.materials.size());
    std::optional<std::uint32_t> all;
    if (v.contains("material")) all = material_named(v["material"], Reader::join(where, "material"));
    std::map<std::string, std::uint32_t> overrides;
    if (v.contains("materials")) {
      std::string at = Reader::join(where, "materials");
      const json& m = v["materials"];
      if (!m.is_object()) r_.fail(at, std::string("expected an object, got ") + m.type_name());
      for (const auto& item : m.items()) {
        bool found = std::any_of(loaded.materials.begin(), loaded.materials.end(),
                                 [&](const MeshMaterial& mm) { return mm.name == item.key(); });
        if (!found) r_.fail(Reader::join(at, item.key()), "the mesh " + file + " has no material of that name");
        overrides[item.key()] = material_named(item.value(), Reader::join(at, item.key()));
      }
    }
    for (std::size_t i = 0; i < loaded.materials.size(); ++i) {
      const MeshMaterial& mm = loaded.materials[i];
      if (all) map[i] = *all;
      else if (auto it = overrides.find(mm.name); it != overrides.end()) map[i] = it->second;
      else {
        // The file's own material: one scene material per file and MTL
        // material, whichever objects load the file.
        auto [made, added] = mtl_materials_.try_emplace({key, i}, static_cast<std::uint32_t>(scene_.materials.size()));
        map[i] = made->second;
        if (!added) continue;
        Material m = material_from_mtl(mm);
        m.name = mm.name + " (" + file + ")";
        scene_.materials.push_back(m);
      }
    }

    SceneMesh mesh;
    mesh.name = path.string();
    // Objects that load the same file with the same materials share its shape.
    std::shared_ptr<const MeshShape>& shape = shapes_[{key, map}];
    if (!shape) {
      auto made = std::make_shared<MeshShape>();
      made->vertices = loaded.geometry.vertices;
      made->triangles = loaded.geometry.triangles;
      made->materials.reserve(loaded.triangle_material.size());
      for (std::uint32_t m : loaded.triangle_material) made->materials.push_back(map.at(m));
      shape = std::move(made);
    }
    mesh.shape = shape;
    if (v.contains("transform")) mesh.transform = read_transform(r_, v["transform"], Reader::join(where, "transform"));
    if (v.contains("motion")) {
      std::string at = Reader::join(where, "motion");
      mesh.end_transform = read_transform(r_, v["motion"], at) * mesh.transform;
      mesh.motion_key = r_.source() + ": " + at;
    }
    scene_.meshes.push_back(std::move(mesh));
  }

  const LoadedMesh& load(const std::string& path, const std::string& where) {
    auto it = meshes_.find(path);
    if (it != meshes_.end()) return it->second;
    try {
      LoadedMesh mesh = load_mesh(path);
      scene_.notes.insert(scene_.notes.end(), mesh.notes.begin(), mesh.notes.end());
      return meshes_.emplace(path, std::move(mesh)).first->second;
    } catch (const Error& e) {
      r_.fail(where, e.what());
    }
  }

  const Reader& r_;
  std::filesystem::path base_dir_;
  SceneDescription scene_;
  std::map<std::string, std::uint32_t> named_;
  std::map<std::string, LoadedMesh> meshes_;
  // The scene material made for (file, its MTL material index).
  std::map<std::pair<std::string, std::size_t>, std::uint32_t> mtl_materials_;
  // The shape of (file, scene material per MTL material).
  std::map<std::pair<std::string, std::vector<std::uint32_t>>, std::shared_ptr<const MeshShape>> shapes_;
};

}  // namespace

Material material_from_mtl(const MeshMaterial& mm) {
  Material m;
  m.name = mm.name;
  m.diffuse = mm.diffuse;
  m.ambient = mm.ambient == glm::vec3(0.0f) ? mm.diffuse : mm.ambient;
  m.specular = mm.specular;
  m.shininess = std::max(mm.shininess, 0.0f);
  m.emission = mm.emission;
  m.ior = mm.ior > 0.0f ? mm.ior : 1.0f;
  m.kt = glm::vec3(std::clamp(1.0f - mm.opacity, 0.0f, 1.0f));
  m.kr = glm::vec3(0.0f);
  return m;
}

SceneDescription parse_scene(const std::string& text, const std::string& source, const std::filesystem::path& base_dir) {
  Reader reader(source);
  json root = parse_strict(text, reader);
  SceneDescription scene = SceneBuilder(reader, base_dir).build(root);
  check_motion(scene, scene.camera.shutter_open, scene.camera.shutter_close);
  return scene;
}

SceneDescription load_scene(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw Error(path + ": is a directory, not a scene file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open the scene file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw Error(path + ": cannot read the scene file");
  std::filesystem::path base = std::filesystem::path(path).parent_path();
  return parse_scene(text.str(), path, base.empty() ? std::filesystem::path(".") : base);
}

}  // namespace rtcl
