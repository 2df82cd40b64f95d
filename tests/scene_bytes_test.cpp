// Scenes through scene_to_bytes / scene_from_bytes: every field back, bit
// for bit; damaged bytes are errors naming their source.
#include <gtest/gtest.h>

#include <cstring>

#include "rtcl/error.hpp"
#include "rtcl/scene/default_scene.hpp"
#include "rtcl/scene/scene_bytes.hpp"
#include "rtcl/scene/scene_file.hpp"

namespace rtcl::test {
namespace {

void expect_same(const SceneDescription& a, const SceneDescription& b) {
  EXPECT_EQ(a.source, b.source);
  EXPECT_EQ(0, std::memcmp(&a.camera, &b.camera, sizeof a.camera));
  EXPECT_EQ(a.ambient, b.ambient);
  EXPECT_EQ(a.background, b.background);
  ASSERT_EQ(a.lights.size(), b.lights.size());
  for (std::size_t i = 0; i < a.lights.size(); ++i) {
    EXPECT_EQ(a.lights[i].position, b.lights[i].position);
    EXPECT_EQ(a.lights[i].color, b.lights[i].color);
    EXPECT_EQ(a.lights[i].intensity, b.lights[i].intensity);
  }
  ASSERT_EQ(a.materials.size(), b.materials.size());
  for (std::size_t i = 0; i < a.materials.size(); ++i) {
    const Material &p = a.materials[i], &q = b.materials[i];
    EXPECT_EQ(p.name, q.name);
    EXPECT_TRUE(p.ambient == q.ambient && p.diffuse == q.diffuse && p.specular == q.specular &&
                p.shininess == q.shininess && p.emission == q.emission && p.kr == q.kr && p.kt == q.kt &&
                p.ior == q.ior)
        << p.name;
  }
  ASSERT_EQ(a.meshes.size(), b.meshes.size());
  for (std::size_t i = 0; i < a.meshes.size(); ++i) {
    EXPECT_EQ(a.meshes[i].name, b.meshes[i].name);
    EXPECT_EQ(a.meshes[i].vertices(), b.meshes[i].vertices());
    EXPECT_EQ(a.meshes[i].triangles(), b.meshes[i].triangles());
    EXPECT_EQ(a.meshes[i].materials(), b.meshes[i].materials());
    EXPECT_EQ(a.meshes[i].transform, b.meshes[i].transform);
  }
  ASSERT_EQ(a.spheres.size(), b.spheres.size());
  for (std::size_t i = 0; i < a.spheres.size(); ++i) {
    EXPECT_EQ(a.spheres[i].center, b.spheres[i].center);
    EXPECT_EQ(a.spheres[i].radius, b.spheres[i].radius);
    EXPECT_EQ(a.spheres[i].material, b.spheres[i].material);
  }
  EXPECT_EQ(a.notes, b.notes);
  EXPECT_EQ(a.precision, b.precision);
  EXPECT_EQ(a.accel, b.accel);
}

TEST(SceneBytes, RoundTripKeepsEveryField) {
  SceneDescription scene = default_scene();
  scene.notes = {"a note"};
  scene.precision = Precision::exact;
  scene.accel = "grid:lambda=4";
  expect_same(scene, scene_from_bytes(scene_to_bytes(scene), "test"));
  SceneDescription file = load_scene(std::string(RTCL_SOURCE_DIR) + "/scenes/cornell.json");
  expect_same(file, scene_from_bytes(scene_to_bytes(file), "test"));
}

TEST(SceneBytes, DamagedBytesAreErrorsNamingTheSource) {
  std::vector<std::byte> bytes = scene_to_bytes(default_scene());
  auto message = [](std::span<const std::byte> b) {
    try {
      scene_from_bytes(b, "the broadcast from rank 0");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  for (std::size_t cut : {std::size_t(0), std::size_t(3), std::size_t(40), bytes.size() / 2, bytes.size() - 1})
    EXPECT_NE(message(std::span(bytes).first(cut)).find("the broadcast from rank 0: not a scene"), std::string::npos)
        << "cut at " << cut;
  std::vector<std::byte> longer = bytes;
  longer.push_back(std::byte{0});
  EXPECT_NE(message(longer).find("extra bytes"), std::string::npos);
  std::vector<std::byte> other = bytes;
  other[0] = std::byte{0};
  EXPECT_NE(message(other).find("magic"), std::string::npos);
}

}  // namespace
}  // namespace rtcl::test
