// The JSON scene file: what it builds (transforms, materials, paths relative
// to the file) and that every mistake is an error naming the file and the key.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "rtcl/error.hpp"
#include "rtcl/scene/default_scene.hpp"
#include "rtcl/scene/scene_file.hpp"
#include "support/temp_dir.hpp"

namespace rtcl::test {
namespace {

const char* triangle_obj =
    "mtllib tri.mtl\n"
    "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
    "usemtl shiny\n"
    "f 1 2 3\n";
const char* triangle_mtl =
    "newmtl shiny\n"
    "Ka 0 0 0\nKd 0.5 0.25 0.125\nKs 0.3 0.3 0.3\nNs 40\nKe 1 2 3\nNi 1.33\nd 0.25\n";

// A scene with a camera and the given "materials" and "objects" text.
std::string scene_text(const std::string& materials, const std::string& objects, const std::string& extra = "") {
  return "{\n  \"camera\": {\"position\": [0, 0, 5], \"look_at\": [0, 0, 0], \"fov\": 40},\n" + extra +
         "  \"materials\": {" + materials + "},\n  \"objects\": [" + objects + "]\n}\n";
}

struct Files {
  TempDir dir;
  Files() {
    dir.write("tri.obj", triangle_obj);
    dir.write("tri.mtl", triangle_mtl);
  }
  // Writes the scene as scene.json and loads it; returns the error message
  // ("" when it loaded).
  std::string error_of(const std::string& text) const {
    std::string path = dir.write("scene.json", text);
    try {
      load_scene(path);
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  }
};

const std::string glass = "\"glass\": {\"diffuse\": 0, \"kt\": 1, \"ior\": 1.5}";
const std::string sphere = "{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"glass\"}";

TEST(SceneFile, ShippedScenesLoad) {
  SceneDescription cornell = load_scene(std::string(RTCL_SOURCE_DIR) + "/scenes/cornell.json");
  ASSERT_EQ(cornell.meshes.size(), 1u);
  EXPECT_EQ(cornell.meshes[0].triangles().size(), 36u);
  ASSERT_EQ(cornell.spheres.size(), 2u);
  EXPECT_NEAR(cornell.spheres[0].radius, 0.2, 1e-12) << "sphere transform applied";
  EXPECT_NEAR(cornell.spheres[0].center.y, 0.8, 1e-12);
  EXPECT_EQ(cornell.lights.size(), 1u);
  // The lamp's MTL emission arrives as a material; the blocks use "white".
  bool lamp = false;
  for (const Material& m : cornell.materials) lamp = lamp || m.emission.x > 10.0f;
  EXPECT_TRUE(lamp);
  FlatScene flat = flatten(cornell);
  EXPECT_EQ(flat.geometry.primitive_count(), 38u);
  EXPECT_EQ(flat.material.size(), 38u);
  for (const char* name : {"/scenes/sibenik.json", "/scenes/sponza.json", "/scenes/cornell_soft.json",
                           "/scenes/sibenik_mirror_beam.json", "/scenes/cornell_glass_beam.json"})
    EXPECT_NO_THROW(load_scene(std::string(RTCL_SOURCE_DIR) + name)) << name;
}

TEST(SceneFile, TransformsMaterialsAndRelativePaths) {
  Files f;
  std::filesystem::create_directory(f.dir.file("sub"));
  // The mesh path is relative to the scene file (in sub/), not to the working directory.
  std::string path = f.dir.write(
      "sub/scene.json",
      scene_text(glass,
                 "{\"type\": \"mesh\", \"file\": \"../tri.obj\",\n"
                 " \"transform\": {\"scale\": 2, \"rotate\": [0, 90, 0], \"translate\": [1, 2, 3]}},\n"
                 "{\"type\": \"mesh\", \"file\": \"../tri.obj\", \"material\": \"glass\"},\n" +
                     sphere,
                 "  // comments are allowed\n  \"ambient\": [0.1, 0.2, 0.3], \"background\": 0.5,\n"
                 "  \"lights\": [{\"position\": [0, 4, 0], \"color\": 0.5, \"intensity\": 2}],\n"));
  SceneDescription scene = load_scene(path);
  EXPECT_EQ(scene.ambient, glm::vec3(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(scene.background, glm::vec3(0.5f));
  ASSERT_EQ(scene.lights.size(), 1u);
  EXPECT_EQ(scene.lights[0].color * scene.lights[0].intensity, glm::vec3(1.0f));
  FlatScene flat = flatten(scene);
  ASSERT_EQ(flat.geometry.triangles.size(), 2u);
  // (1, 0, 0) scaled by 2, rotated 90 degrees about y (x -> -z), moved by (1, 2, 3)
  glm::vec3 v1 = flat.geometry.vertices[flat.geometry.triangles[0][1]];
  EXPECT_NEAR(v1.x, 1.0f, 1e-5f);
  EXPECT_NEAR(v1.y, 2.0f, 1e-5f);
  EXPECT_NEAR(v1.z, 1.0f, 1e-5f);
  // MTL mapping of the first mesh; the override of the second.
  const Material& mtl = scene.materials[flat.material[0]];
  EXPECT_EQ(mtl.diffuse, glm::vec3(0.5f, 0.25f, 0.125f));
  EXPECT_EQ(mtl.ambient, mtl.diffuse) << "black Ka becomes Kd";
  EXPECT_EQ(mtl.specular, glm::vec3(0.3f));
  EXPECT_EQ(mtl.shininess, 40.0f);
  EXPECT_EQ(mtl.emission, glm::vec3(1.0f, 2.0f, 3.0f));
  EXPECT_NEAR(mtl.ior, 1.33f, 1e-6f);
  EXPECT_NEAR(mtl.kt.x, 0.75f, 1e-6f) << "kt = 1 - d";
  EXPECT_EQ(scene.materials[flat.material[1]].name, "glass");
  EXPECT_EQ(scene.materials[flat.material[2]].name, "glass");
}

TEST(SceneFile, AreaLightsLensAndRoughness) {
  Files f;
  std::string text =
      "{\n  \"camera\": {\"position\": [0, 0, 5], \"look_at\": [0, 0, 0], \"aperture\": 0.1, \"focus_distance\": 4},\n"
      "  \"lights\": [{\"type\": \"quad\", \"position\": [0, 2, 0], \"edge1\": [0.5, 0, 0], \"edge2\": [0, 0, 0.25]},\n"
      "             {\"type\": \"disc\", \"position\": [1, 2, 0], \"normal\": [0, -2, 0], \"radius\": 0.3},\n"
      "             {\"type\": \"sphere\", \"position\": [-1, 2, 0], \"radius\": 0.2, \"intensity\": 2},\n"
      "             {\"position\": [0, 3, 0]}, {\"type\": \"emissive\", \"intensity\": 0.1}],\n"
      "  \"materials\": {\"satin\": {\"kr\": 0.5, \"roughness\": 0.3}},\n"
      "  \"objects\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"satin\"}]\n}\n";
  SceneDescription scene = load_scene(f.dir.write("scene.json", text));
  EXPECT_EQ(scene.camera.aperture, 0.1f);
  EXPECT_EQ(scene.camera.focus_distance, 4.0f);
  ASSERT_EQ(scene.lights.size(), 5u);
  EXPECT_EQ(scene.lights[4].shape, LightShape::emissive);
  EXPECT_EQ(scene.lights[0].shape, LightShape::quad);
  EXPECT_EQ(scene.lights[0].edge2, glm::vec3(0.0f, 0.0f, 0.25f));
  EXPECT_EQ(scene.lights[1].shape, LightShape::disc);
  EXPECT_EQ(scene.lights[1].normal, glm::vec3(0.0f, -2.0f, 0.0f));
  EXPECT_EQ(scene.lights[1].radius, 0.3f);
  EXPECT_EQ(scene.lights[2].shape, LightShape::sphere);
  EXPECT_EQ(scene.lights[3].shape, LightShape::point);
  ASSERT_EQ(scene.materials.size(), 1u);
  EXPECT_EQ(scene.materials[0].roughness, 0.3f);
  EXPECT_TRUE(scene.materials[0].glossy());
}

TEST(SceneFile, PlyAndStlMeshes) {
  Files f;
  f.dir.write("tri.stl",
              "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n"
              "endfacet\nendsolid t\n");
  f.dir.write("tri.ply",
              "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
              "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  SceneDescription scene = load_scene(f.dir.write(
      "scene.json", scene_text(glass, "{\"type\": \"mesh\", \"file\": \"tri.stl\", \"material\": \"glass\"},"
                                      "{\"type\": \"mesh\", \"file\": \"tri.ply\", "
                                      "\"transform\": {\"translate\": [0, 0, 2]}}")));
  FlatScene flat = flatten(scene);
  ASSERT_EQ(flat.geometry.triangles.size(), 2u);
  EXPECT_EQ(scene.materials[flat.material[0]].name, "glass");
  EXPECT_EQ(flat.geometry.vertices[flat.geometry.triangles[1][0]].z, 2.0f);
}

TEST(SceneFile, MirroringTransformKeepsFacesOutward) {
  Files f;
  SceneDescription plain = load_scene(f.dir.write("a.json", scene_text(glass, "{\"type\": \"mesh\", \"file\": \"tri.obj\"}")));
  SceneDescription mirrored = load_scene(f.dir.write(
      "b.json", scene_text(glass, "{\"type\": \"mesh\", \"file\": \"tri.obj\", \"transform\": {\"scale\": [1, 1, -1]}}")));
  auto normal_z = [](const SceneDescription& s) {
    FlatScene flat = flatten(s);
    const auto& g = flat.geometry;
    glm::vec3 a = g.vertices[g.triangles[0][0]], b = g.vertices[g.triangles[0][1]], c = g.vertices[g.triangles[0][2]];
    return glm::cross(b - a, c - a).z;
  };
  EXPECT_GT(normal_z(plain), 0.0f);
  EXPECT_LT(normal_z(mirrored), 0.0f) << "the mirror image of a +z face faces -z";
}

// Each bad file: the message names the file, the key and the problem.
TEST(SceneFile, BadFilesGiveClearErrors) {
  Files f;
  struct Case {
    std::string text;
    std::vector<std::string> fragments;
  };
  const std::string tri = "{\"type\": \"mesh\", \"file\": \"tri.obj\"}";
  const Case cases[] = {
      {scene_text(glass, "{\"type\": \"mesh\", \"file\": \"missing.obj\"}"),
       {"objects[0].file", "missing.obj"}},
      {scene_text(glass, sphere + ", {\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"glas\"}"),
       {"objects[1].material", "unknown material 'glas'", "glass"}},
      {scene_text(glass, sphere) + "}", {"malformed JSON", "line"}},
      {"{\"camera\": {\"position\": [0, 0, 5], \"look_at\": [0, 0, 0]},, \"objects\": []}", {"malformed JSON", "line 1"}},
      {scene_text("\"glass\": {\"kt\": 1, \"ior\": -1.5}", sphere), {"materials.glass.ior", "positive", "-1.5"}},
      {scene_text("\"glass\": {\"kt\": 1, \"ior\": 0}", sphere), {"materials.glass.ior", "positive"}},
      {scene_text(glass, sphere, "  \"lights\": [{\"position\": [0, 1, 0], \"intensity\": \"bright\"}],\n"),
       {"lights[0].intensity", "expected a number, got string"}},
      {scene_text(glass, sphere, "  \"ambiant\": 0.1,\n"), {"ambiant", "unknown key"}},
      {scene_text("\"glass\": {\"kt\": 1, \"rougness\": 0.5}", sphere), {"materials.glass.rougness", "unknown key"}},
      {scene_text("\"glass\": {\"kt\": 1, \"roughness\": 1.5}", sphere), {"materials.glass.roughness", "[0, 1]", "1.5"}},
      {scene_text("\"glass\": {\"kt\": 1, \"roughness\": -0.1}", sphere), {"materials.glass.roughness", "[0, 1]"}},
      {scene_text(glass, sphere, "  \"lights\": [{\"type\": \"tube\", \"position\": [0, 1, 0]}],\n"),
       {"lights[0].type", "unknown light type 'tube'", "quad"}},
      {scene_text(glass, sphere, "  \"lights\": [{\"type\": \"sphere\", \"position\": [0, 1, 0], \"radius\": -1}],\n"),
       {"lights[0].radius", "must not be negative"}},
      {scene_text(glass, sphere, "  \"lights\": [{\"type\": \"disc\", \"position\": [0, 1, 0], \"radius\": 1, "
                                 "\"normal\": [0, 0, 0]}],\n"),
       {"lights[0].normal", "must not be zero"}},
      {scene_text(glass, sphere, "  \"lights\": [{\"type\": \"disc\", \"position\": [0, 1, 0], \"radius\": 1}],\n"),
       {"lights[0]", "missing required key 'normal'"}},
      {scene_text(glass, sphere, "  \"lights\": [{\"type\": \"quad\", \"position\": [0, 1, 0], \"radius\": 1}],\n"),
       {"lights[0].radius", "not a key of a quad light"}},
      {scene_text(glass, sphere, "  \"lights\": [{\"position\": [0, 1, 0], \"edge1\": [1, 0, 0]}],\n"),
       {"lights[0].edge1", "not a key of a point light"}},
      {scene_text(glass, sphere, "  \"lights\": [{\"type\": \"emissive\", \"position\": [0, 1, 0]}],\n"),
       {"lights[0].position", "not a key of an emissive light"}},
      {scene_text(glass, "{\"type\": \"sphere\", \"center\": [0, 0], \"radius\": 1, \"material\": \"glass\"}"),
       {"objects[0].center", "3 numbers"}},
      {scene_text(glass, "{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": -1, \"material\": \"glass\"}"),
       {"objects[0].radius", "positive"}},
      {scene_text(glass, "{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"glass\", "
                         "\"transform\": {\"scale\": [1, 2, 1]}}"),
       {"objects[0].transform", "uniform"}},
      {scene_text(glass, "{\"type\": \"cube\"}"), {"objects[0].type", "unknown object type 'cube'"}},
      {scene_text(glass, ""), {"objects", "at least one object"}},
      {scene_text("\"m\": {\"kr\": 1.5}", tri), {"materials.m.kr", "[0, 1]"}},
      {scene_text(glass, "{\"type\": \"mesh\", \"file\": \"tri.obj\", \"materials\": {\"nosuch\": \"glass\"}}"),
       {"objects[0].materials.nosuch", "no material of that name"}},
      {"{\"objects\": [" + tri + "]}", {"missing required key 'camera'"}},
      {"{\"camera\": {\"position\": [0, 0, 5], \"look_at\": [0, 0, 5]}, \"objects\": [" + tri + "]}",
       {"camera", "same point"}},
      {"{\"camera\": {\"position\": [0, 0, 5], \"look_at\": [0, 0, 0], \"fov\": 200}, \"objects\": [" + tri + "]}",
       {"camera.fov", "(0, 180)"}},
      {"{\"camera\": {\"position\": [0, 0, 5], \"look_at\": [0, 0, 0], \"aperture\": -0.1}, \"objects\": [" + tri + "]}",
       {"camera.aperture", "must not be negative", "-0.1"}},
      {"{\"camera\": {\"position\": [0, 0, 5], \"look_at\": [0, 0, 0], \"focus_distance\": 0}, \"objects\": [" + tri +
           "]}",
       {"camera.focus_distance", "must be positive"}},
      {"{\"camera\": {\"position\": [0, 0, 5], \"position\": [0, 0, 4], \"look_at\": [0, 0, 0]}, \"objects\": [" + tri +
           "]}",
       {"duplicate key 'position'"}},
      {"[1, 2, 3]", {"expected an object"}},
  };
  for (const Case& c : cases) {
    std::string message = f.error_of(c.text);
    ASSERT_FALSE(message.empty()) << "accepted:\n" << c.text;
    EXPECT_NE(message.find("scene.json"), std::string::npos) << message;
    for (const std::string& fragment : c.fragments)
      EXPECT_NE(message.find(fragment), std::string::npos) << "'" << fragment << "' missing from: " << message;
  }
  try {
    load_scene(f.dir.file("nothere.json"));
    ADD_FAILURE() << "a missing scene file loaded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("nothere.json"), std::string::npos) << e.what();
  }
}

TEST(Scene, DefaultSceneShowsEveryEffect) {
  SceneDescription s = default_scene();
  validate(s);
  bool mirror = false, glass_sphere = false, glass_mesh = false, emissive = false;
  FlatScene flat = flatten(s);
  for (std::size_t p = 0; p < flat.material.size(); ++p) {
    const Material& m = s.materials[flat.material[p]];
    bool sphere = p >= flat.geometry.triangles.size();
    mirror = mirror || (sphere && m.reflective());
    glass_sphere = glass_sphere || (sphere && m.transmissive() && m.ior > 1.0f);
    glass_mesh = glass_mesh || (!sphere && m.transmissive());
    emissive = emissive || m.emission.x > 0.0f;
  }
  EXPECT_TRUE(mirror && glass_sphere && glass_mesh && emissive);
  EXPECT_EQ(s.lights.size(), 1u) << "one point light: hard shadows";
}

TEST(Scene, InvalidScenesAreRejected) {
  SceneDescription s = default_scene();
  s.materials[0].ior = -1.0f;
  EXPECT_THROW(validate(s), Error);
  s = default_scene();
  s.camera.up = glm::vec3(0.0f, 0.0f, 1.0f);  // parallel to the view direction
  EXPECT_THROW(validate(s), Error);
  s = default_scene();
  s.meshes[0].edit_shape().materials[0] = 99;
  EXPECT_THROW(flatten(s), Error);
  s = default_scene();
  EXPECT_THROW(transform_scene(s, glm::dmat4(glm::dvec4(1, 0, 0, 0), glm::dvec4(0, 2, 0, 0), glm::dvec4(0, 0, 1, 0),
                                              glm::dvec4(0, 0, 0, 1))),
               Error)
      << "spheres need a similarity";
}

}  // namespace
}  // namespace rtcl::test
