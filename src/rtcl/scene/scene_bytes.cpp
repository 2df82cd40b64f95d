#include "rtcl/scene/scene_bytes.hpp"

#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <type_traits>

#include "rtcl/error.hpp"

namespace rtcl {

namespace {

constexpr std::uint32_t magic = 0x6c637472u;  // "rtcl"
constexpr std::uint32_t version = 3;  // 2: roughness, motion keyframes; 3: shared mesh shapes

class Writer {
 public:
  template <class T>
  void pod(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const std::byte*>(&value);
    out.insert(out.end(), p, p + sizeof(T));
  }
  template <class T>
  void array(const std::vector<T>& values) {
    static_assert(std::is_trivially_copyable_v<T>);
    pod(std::uint64_t(values.size()));
    const auto* p = reinterpret_cast<const std::byte*>(values.data());
    out.insert(out.end(), p, p + values.size() * sizeof(T));
  }
  void text(const std::string& s) {
    pod(std::uint64_t(s.size()));
    const auto* p = reinterpret_cast<const std::byte*>(s.data());
    out.insert(out.end(), p, p + s.size());
  }
  std::vector<std::byte> out;
};

class Reader {
 public:
  Reader(std::span<const std::byte> bytes, const std::string& what) : bytes_(bytes), what_(what) {}
  template <class T>
  T pod() {
    T value;
    std::memcpy(&value, take(sizeof(T), 1), sizeof(T));
    return value;
  }
  template <class T>
  std::vector<T> array() {
    std::uint64_t n = pod<std::uint64_t>();
    std::vector<T> values(static_cast<std::size_t>(n <= remaining() / sizeof(T) ? n : 0));
    const std::byte* p = take(sizeof(T), n);
    if (n > 0) std::memcpy(values.data(), p, n * sizeof(T));
    return values;
  }
  std::string text() {
    std::uint64_t n = pod<std::uint64_t>();
    const std::byte* p = take(1, n);
    return std::string(reinterpret_cast<const char*>(p), static_cast<std::size_t>(n));
  }
  // Counts of records that hold variable-length fields: at least one byte each.
  std::size_t count() {
    std::uint64_t n = pod<std::uint64_t>();
    if (n > remaining()) fail("a count of " + std::to_string(n) + " with " + std::to_string(remaining()) + " bytes left");
    return static_cast<std::size_t>(n);
  }
  std::size_t remaining() const { return bytes_.size() - at_; }
  [[noreturn]] void fail(const std::string& why) const {
    throw Error(what_ + ": not a scene of this rtcl build (" + why + " at byte " + std::to_string(at_) + ")");
  }

 private:
  const std::byte* take(std::size_t size, std::uint64_t n) {
    if (n > remaining() / size) fail("truncated: " + std::to_string(n * size) + " bytes wanted");
    const std::byte* p = bytes_.data() + at_;
    at_ += static_cast<std::size_t>(n * size);
    return p;
  }
  std::span<const std::byte> bytes_;
  const std::string& what_;
  std::size_t at_ = 0;
};

}  // namespace

std::vector<std::byte> scene_to_bytes(const SceneDescription& scene) {
  Writer w;
  w.pod(magic);
  w.pod(version);
  w.text(scene.source);
  w.pod(scene.camera);
  w.pod(scene.ambient);
  w.pod(scene.background);
  w.array(scene.lights);
  w.pod(std::uint64_t(scene.materials.size()));
  for (const Material& m : scene.materials) {
    w.text(m.name);
    w.pod(m.ambient);
    w.pod(m.diffuse);
    w.pod(m.specular);
    w.pod(m.shininess);
    w.pod(m.emission);
    w.pod(m.kr);
    w.pod(m.kt);
    w.pod(m.ior);
    w.pod(m.roughness);
  }
  // Each shape once, in the order of its first mesh; each mesh names its
  // shape by that order, so meshes that share a shape share it after
  // decoding too.
  std::map<const MeshShape*, std::uint64_t> shape_index;
  std::vector<const MeshShape*> shapes;
  for (const SceneMesh& m : scene.meshes)
    if (shape_index.try_emplace(m.shape.get(), shapes.size()).second) shapes.push_back(m.shape.get());
  w.pod(std::uint64_t(shapes.size()));
  for (const MeshShape* shape : shapes) {
    w.array(shape->vertices);
    w.array(shape->triangles);
    w.array(shape->materials);
  }
  w.pod(std::uint64_t(scene.meshes.size()));
  for (const SceneMesh& m : scene.meshes) {
    w.text(m.name);
    w.pod(shape_index.at(m.shape.get()));
    w.pod(m.transform);
    w.pod(std::uint8_t(m.end_transform.has_value()));
    if (m.end_transform) w.pod(*m.end_transform);
    w.text(m.motion_key);
  }
  w.pod(std::uint64_t(scene.spheres.size()));
  for (const SceneSphere& s : scene.spheres) {
    w.pod(s.center);
    w.pod(s.radius);
    w.pod(s.material);
    w.pod(std::uint8_t(s.moving));
    w.pod(s.end_center);
    w.pod(s.end_radius);
    w.text(s.motion_key);
  }
  w.pod(std::uint64_t(scene.notes.size()));
  for (const std::string& note : scene.notes) w.text(note);
  w.pod(std::int32_t(scene.precision ? static_cast<int>(*scene.precision) : -1));
  w.text(scene.accel);
  return std::move(w.out);
}

SceneDescription scene_from_bytes(std::span<const std::byte> bytes, const std::string& what) {
  Reader r(bytes, what);
  if (r.pod<std::uint32_t>() != magic) r.fail("another magic");
  if (std::uint32_t v = r.pod<std::uint32_t>(); v != version) r.fail("version " + std::to_string(v));
  SceneDescription scene;
  scene.source = r.text();
  scene.camera = r.pod<Camera>();
  scene.ambient = r.pod<glm::vec3>();
  scene.background = r.pod<glm::vec3>();
  scene.lights = r.array<PointLight>();
  scene.materials.resize(r.count());
  for (Material& m : scene.materials) {
    m.name = r.text();
    m.ambient = r.pod<glm::vec3>();
    m.diffuse = r.pod<glm::vec3>();
    m.specular = r.pod<glm::vec3>();
    m.shininess = r.pod<float>();
    m.emission = r.pod<glm::vec3>();
    m.kr = r.pod<glm::vec3>();
    m.kt = r.pod<glm::vec3>();
    m.ior = r.pod<float>();
    m.roughness = r.pod<float>();
  }
  std::vector<std::shared_ptr<const MeshShape>> shapes(r.count());
  for (std::shared_ptr<const MeshShape>& shape : shapes) {
    auto made = std::make_shared<MeshShape>();
    made->vertices = r.array<glm::vec3>();
    made->triangles = r.array<glm::uvec3>();
    made->materials = r.array<std::uint32_t>();
    shape = std::move(made);
  }
  scene.meshes.resize(r.count());
  for (SceneMesh& m : scene.meshes) {
    m.name = r.text();
    auto shape = r.pod<std::uint64_t>();
    if (shape >= shapes.size()) r.fail("mesh shape " + std::to_string(shape) + " of " + std::to_string(shapes.size()));
    m.shape = shapes[shape];
    m.transform = r.pod<glm::dmat4>();
    if (r.pod<std::uint8_t>()) m.end_transform = r.pod<glm::dmat4>();
    m.motion_key = r.text();
  }
  scene.spheres.resize(r.count());
  for (SceneSphere& s : scene.spheres) {
    s.center = r.pod<glm::dvec3>();
    s.radius = r.pod<double>();
    s.material = r.pod<std::uint32_t>();
    s.moving = r.pod<std::uint8_t>() != 0;
    s.end_center = r.pod<glm::dvec3>();
    s.end_radius = r.pod<double>();
    s.motion_key = r.text();
  }
  scene.notes.resize(r.count());
  for (std::string& note : scene.notes) note = r.text();
  std::int32_t precision = r.pod<std::int32_t>();
  if (precision < -1 || precision > static_cast<int>(Precision::exact)) r.fail("precision " + std::to_string(precision));
  if (precision >= 0) scene.precision = static_cast<Precision>(precision);
  scene.accel = r.text();
  if (r.remaining() != 0) r.fail(std::to_string(r.remaining()) + " extra bytes");
  return scene;
}

}  // namespace rtcl
