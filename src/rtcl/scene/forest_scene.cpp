#include "rtcl/scene/forest_scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>

#include <glm/gtc/matrix_transform.hpp>

#include "rtcl/error.hpp"
#include "rtcl/scene/mesh_io.hpp"

namespace rtcl {

namespace {

// splitmix64 (Steele, Lea and Flood 2014): the same numbers on every
// platform, unlike the standard library's distributions.
struct Random {
  std::uint64_t state;
  double next() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) * 0x1.0p-53;  // [0, 1)
  }
  double between(double lo, double hi) { return lo + (hi - lo) * next(); }
};

}  // namespace

SceneDescription forest_scene(const std::string& bunny_path, const ForestOptions& options) {
  if (options.bunnies == 0) throw Error("forest scene: bunnies must be at least 1");
  LoadedMesh loaded;
  try {
    loaded = load_mesh(bunny_path);
  } catch (const Error& e) {
    throw Error("forest scene: the Stanford bunny (" + bunny_path + ") cannot be read: " + e.what());
  }
  SceneDescription s;
  s.source = "forest scene";
  s.notes = loaded.notes;
  Material fur;
  fur.name = "bunny";
  fur.diffuse = fur.ambient = {0.78f, 0.72f, 0.62f};
  fur.specular = glm::vec3(0.15f);
  fur.shininess = 20.0f;
  Material grass;
  grass.name = "ground";
  grass.diffuse = grass.ambient = {0.33f, 0.48f, 0.22f};
  s.materials = {fur, grass};

  auto bunny = std::make_shared<MeshShape>();
  bunny->vertices = std::move(loaded.geometry.vertices);
  bunny->triangles = std::move(loaded.geometry.triangles);
  bunny->materials.assign(bunny->triangles.size(), 0);
  // The bunny 1 unit tall, standing on y = 0 and centred on the vertical axis.
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::vec3& v : bunny->vertices) {
    lo = glm::min(lo, glm::dvec3(v));
    hi = glm::max(hi, glm::dvec3(v));
  }
  const double height = hi.y - lo.y;
  if (!(height > 0.0)) throw Error("forest scene: the bunny (" + bunny_path + ") has no height");
  const glm::dmat4 unit = glm::scale(glm::dmat4(1.0), glm::dvec3(1.0 / height)) *
                          glm::translate(glm::dmat4(1.0), -glm::dvec3(0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z)));

  // Rows along x, from the back (z = -L/2) to the front (z = +L/2), one
  // unit apart; the camera looks from beyond the front row.
  const auto side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(options.bunnies))));
  const double L = static_cast<double>(side);
  const std::size_t front_row = (options.bunnies - 1) / side;
  const std::size_t in_front = options.bunnies - front_row * side;
  const std::size_t moving = std::min(options.moving, in_front);
  const std::size_t first_moving = (in_front - moving) / 2;
  std::shared_ptr<const MeshShape> shared = bunny;
  Random random{0x5eedf0e57ull};
  for (std::size_t k = 0; k < options.bunnies; ++k) {
    const std::size_t row = k / side, col = k % side;
    const double x = (static_cast<double>(col) + 0.5 - 0.5 * L) + random.between(-0.2, 0.2);
    const double z = (static_cast<double>(row) + 0.5 - 0.5 * L) + random.between(-0.2, 0.2);
    const double turn = random.between(0.0, 360.0);
    const double size = random.between(0.45, 0.8);
    SceneMesh m;
    m.name = bunny_path;
    m.shape = shared;
    m.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(x, 0.0, z)) *
                  glm::rotate(glm::dmat4(1.0), glm::radians(turn), glm::dvec3(0, 1, 0)) *
                  glm::scale(glm::dmat4(1.0), glm::dvec3(size)) * unit;
    if (row == front_row && col >= first_moving && col < first_moving + moving) {
      // A hop forwards: 0.3 along +z and 0.15 up over one keyframe.
      m.end_transform = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.15, 0.3)) * m.transform;
      m.motion_key = "forest scene: bunny " + std::to_string(k) + "'s hop";
    }
    s.meshes.push_back(std::move(m));
  }
  // The ground: a square a unit beyond the grid on every side, facing up.
  auto ground = std::make_shared<MeshShape>();
  const float g = static_cast<float>(0.5 * L + 1.0);
  ground->vertices = {{-g, 0, -g}, {g, 0, -g}, {g, 0, g}, {-g, 0, g}};
  ground->triangles = {{0, 2, 1}, {0, 3, 2}};  // normal +y
  ground->materials = {1, 1};
  SceneMesh plane;
  plane.name = "ground";
  plane.shape = ground;
  s.meshes.push_back(std::move(plane));

  // A walker's view: low, a few units beyond the front row, down the rows
  // to the horizon.
  s.camera.position = glm::vec3(glm::dvec3(0.0, 2.5, 0.5 * L + 4.0));
  s.camera.look_at = glm::vec3(glm::dvec3(0.0, 0.4, 0.5 * L - 8.0));
  s.camera.fov_deg = 45.0f;
  s.camera.aspect = 16.0f / 9.0f;
  s.ambient = glm::vec3(0.25f);
  s.background = {0.55f, 0.7f, 0.9f};
  Light sun;
  sun.position = glm::vec3(glm::dvec3(0.4 * L, 2.0 * L, 1.0 * L));
  sun.color = {1.0f, 0.96f, 0.88f};
  s.lights.push_back(sun);
  return s;
}

}  // namespace rtcl
