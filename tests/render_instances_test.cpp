// Scene files that reuse a mesh, and the built-in forest, render through
// two levels (Renderer::instanced): one bottom level per shared shape, the
// image of the same scene through the flat path, `--frames`' re-placing
// of moving objects equal to renderers built for each frame, and the
// forest in the memory of one bunny plus its instance records.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "rtcl/accel.hpp"
#include "rtcl/error.hpp"
#include "rtcl/render/instanced_scene.hpp"
#include "rtcl/render/renderer.hpp"
#include "rtcl/render/render_layouts.hpp"
#include "rtcl/scene/forest_scene.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "rtcl/scene/scene_bytes.hpp"
#include "rtcl/scene/scene_file.hpp"
#include "rtcl/scene/showcase_scene.hpp"
#include "support/cli_run.hpp"
#include "support/error_of.hpp"
#include "support/fixtures.hpp"
#include "support/temp_dir.hpp"

namespace rtcl::test {
namespace {

// A unit cube [-0.5, 0.5]^3 with outward faces (12 triangles), and a floor
// quad facing +y.
const char* cube_obj =
    "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv -0.5 0.5 -0.5\nv 0.5 0.5 -0.5\n"
    "v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv -0.5 0.5 0.5\nv 0.5 0.5 0.5\n"
    "f 1 5 7\nf 1 7 3\nf 2 4 8\nf 2 8 6\nf 1 2 6\nf 1 6 5\n"
    "f 3 7 8\nf 3 8 4\nf 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\n";
const char* floor_obj = "v -4 0 -4\nv 4 0 -4\nv 4 0 4\nv -4 0 4\nf 1 3 2\nf 1 4 3\n";

// Four objects of cube.obj in white (one shape: turned, mirrored,
// non-uniformly scaled), one in glass (a second shape, mirrored: refraction
// tells inside from outside by the winding), the floor, a mirror sphere and, with `motion`, a moving white cube and a moving sphere.
std::string scene_json(bool motion) {
  std::string moving =
      motion ? R"(, {"type": "mesh", "file": "cube.obj", "material": "white",
                    "transform": {"scale": 0.4, "translate": [-1.2, 1.4, 0.5]}, "motion": {"translate": [0.6, 0.1, 0]}},
                  {"type": "sphere", "center": [1.1, 1.5, 0.6], "radius": 0.2, "material": "red",
                   "motion": {"translate": [-0.4, 0.2, 0]}})"
             : "";
  return R"({"camera": {"position": [0.3, 2.2, 5.0], "look_at": [0, 0.6, 0], "fov": 45, "shutter": [0, 1]},
    "ambient": 0.1,
    "lights": [{"position": [1.5, 4, 2.5]}, {"position": [-2, 3, 1], "color": 0.4}],
    "materials": {"white": {"diffuse": 0.7, "specular": 0.2, "shininess": 30},
                  "red": {"diffuse": [0.8, 0.1, 0.1]},
                  "mirror": {"diffuse": 0.05, "kr": 0.9},
                  "glass": {"diffuse": 0, "kt": 0.9, "ior": 1.5}},
    "objects": [
      {"type": "mesh", "file": "floor.obj", "material": "white"},
      {"type": "mesh", "file": "cube.obj", "material": "white", "transform": {"translate": [-1.2, 0.5, -0.6]}},
      {"type": "mesh", "file": "cube.obj", "material": "white",
       "transform": {"rotate": [0, 35, 0], "translate": [0.2, 0.5, -1.2]}},
      {"type": "mesh", "file": "cube.obj", "material": "white",
       "transform": {"scale": [-0.6, 1.4, 0.8], "translate": [1.4, 0.7, -0.4]}},
      {"type": "mesh", "file": "cube.obj", "material": "white",
       "transform": {"scale": [0.5, 0.3, 1.2], "rotate": [20, 0, 10], "translate": [-0.3, 0.3, 1.0]}},
      {"type": "mesh", "file": "cube.obj", "material": "glass",
       "transform": {"scale": [-0.6, 0.6, 0.6], "translate": [0.9, 0.31, 0.9]}},
      {"type": "sphere", "center": [-0.1, 0.45, 0.1], "radius": 0.45, "material": "mirror"})" +
         moving + "]}";
}

struct SceneFiles {
  TempDir dir;
  SceneDescription load(bool motion) const {
    dir.write("cube.obj", cube_obj);
    dir.write("floor.obj", floor_obj);
    return load_scene(dir.write("scene.json", scene_json(motion)));
  }
};

RenderSettings small_settings() {
  RenderSettings s;
  s.width = 64;
  s.height = 48;
  s.max_depth = 4;
  return s;
}

TEST(RenderInstances, SceneFileObjectsOfOneMeshShareItsShape) {
  SceneDescription scene = SceneFiles().load(false);
  ASSERT_EQ(scene.meshes.size(), 6u);
  for (int i = 2; i <= 4; ++i) EXPECT_EQ(scene.meshes[i].shape, scene.meshes[1].shape) << i;
  EXPECT_NE(scene.meshes[5].shape, scene.meshes[1].shape) << "another material assignment: another shape";
  EXPECT_TRUE(shares_meshes(scene));
  EXPECT_FALSE(shares_meshes(unshare_meshes(scene)));
  // The broadcast form keeps the sharing.
  SceneDescription back = scene_from_bytes(scene_to_bytes(scene), "bytes");
  for (int i = 2; i <= 4; ++i) EXPECT_EQ(back.meshes[i].shape, back.meshes[1].shape) << i;
  EXPECT_NE(back.meshes[5].shape, back.meshes[1].shape);
  EXPECT_EQ(back.meshes[3].triangles(), scene.meshes[3].triangles());
}

TEST(RenderInstances, OneBottomLevelPerSharedShape) {
  SceneDescription scene = SceneFiles().load(false);
  Renderer renderer(test_device(), scene, "bvh");
  ASSERT_TRUE(renderer.instanced());
  const SceneStats st = renderer.scene()->stats();
  // floor, white cube, glass cube, the spheres: 4 meshes; 6 mesh objects + the spheres.
  EXPECT_EQ(st.bottom_levels_built, 4u);
  EXPECT_EQ(st.meshes, 4u);
  EXPECT_EQ(st.instances, 7u);
  Renderer flat(test_device(), unshare_meshes(scene), "bvh");
  EXPECT_FALSE(flat.instanced());
  EXPECT_EQ(flat.scene(), nullptr);
}

// The two-level image against the flat path's of the same scene: equal up
// to the float rounding of world-space vertices (flatten rounds the double
// transform; the shade kernel transforms in float), which moves a hit or a
// shadow edge by a pixel at most at a few silhouettes.
TEST(RenderInstances, InstancedImageMatchesTheFlatPath) {
  SceneDescription scene = SceneFiles().load(false);
  RenderSettings settings = small_settings();
  Renderer instanced(test_device(), scene, "bvh");
  Renderer flat(test_device(), unshare_meshes(scene), "bvh");
  ASSERT_TRUE(instanced.instanced());
  EXPECT_EQ(instanced.defines(), [&] {
    auto d = flat.defines();
    d.push_back("RTCL_HAS_INSTANCES");
    return d;
  }()) << "the same specialisation, plus instances";
  Image a = instanced.render(settings), b = flat.render(settings);
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  std::size_t off = 0;
  double sum = 0.0, peak = 0.0;
  for (std::size_t p = 0; p < a.rgb.size() / 3; ++p) {
    double d = 0.0;
    for (int c = 0; c < 3; ++c) d = std::max(d, double(std::abs(a.rgb[p * 3 + c] - b.rgb[p * 3 + c])));
    sum += d;
    peak = std::max(peak, std::max({double(b.rgb[p * 3]), double(b.rgb[p * 3 + 1]), double(b.rgb[p * 3 + 2])}));
    if (d > 1e-3) ++off;
  }
  const std::size_t pixels = a.rgb.size() / 3;
  EXPECT_GT(peak, 0.2) << "the scene is lit";
  EXPECT_LE(off, pixels / 100) << "pixels that differ by more than 1e-3";
  EXPECT_LT(sum / pixels, 2e-3) << "mean difference";
  EXPECT_EQ(instanced.stats().rays.camera, flat.stats().rays.camera);
}

// `--frames`: one renderer re-placed per frame gives each frame's image bit
// for bit as a renderer built for that frame's shutter, and rebuilds the
// top level only.
TEST(RenderInstances, FramesReplaceOnlyMovingObjectsAndMatchSingleFrames) {
  SceneDescription scene = SceneFiles().load(true);
  RenderSettings settings = small_settings();
  settings.spp = 2;
  Renderer animated(test_device(), scene, "bvh");
  ASSERT_TRUE(animated.instanced());
  EXPECT_NE(std::find(animated.defines().begin(), animated.defines().end(), "RTCL_HAS_MOVING_INSTANCES"),
            animated.defines().end());
  const std::size_t bottoms = animated.scene()->stats().bottom_levels_built;
  const std::size_t tops = animated.scene()->stats().top_levels_built;
  for (int frame = 0; frame < 3; ++frame) {
    SceneDescription alone = scene;
    alone.camera.shutter_open = static_cast<float>(scene.camera.shutter_open + frame * 0.75);
    alone.camera.shutter_close = static_cast<float>(scene.camera.shutter_close + frame * 0.75);
    if (frame > 0) {
      CommitStats commit = animated.set_shutter(alone.camera.shutter_open, alone.camera.shutter_close);
      EXPECT_EQ(commit.bottom_levels_built, 0u) << frame;
      EXPECT_TRUE(commit.top_level_built) << frame;
    }
    Image a = animated.render(settings);
    Renderer single(test_device(), alone, "bvh");
    Image b = single.render(settings);
    EXPECT_EQ(a.rgb, b.rgb) << "frame " << frame;
  }
  EXPECT_EQ(animated.scene()->stats().bottom_levels_built, bottoms) << "no bottom level rebuilt";
  EXPECT_EQ(animated.scene()->stats().top_levels_built, tops + 2);
  // The flat path has no re-placing.
  Renderer flat(test_device(), unshare_meshes(scene), "bvh");
  EXPECT_NE(error_of([&] { flat.set_shutter(1.0f, 2.0f); }).find("flat path"), std::string::npos);
}

// A long animation on one renderer holds no more device buffers as it goes:
// re-placing the moving objects replaces the top level, it does not add one
// per frame. A buffer may grow to a larger placement's needs and stay (a
// few steps); a leak grows at every frame.
TEST(RenderInstances, FramesHoldNoMoreDeviceBuffersAsTheAnimationGoesOn) {
  SceneDescription scene = SceneFiles().load(true);
  RenderSettings settings = small_settings();
  settings.width = 16;
  settings.height = 12;
  Device device = Device::open();  // its own count of live buffers
  Renderer animated(device, scene, "bvh");
  ASSERT_TRUE(animated.instanced());
  std::vector<std::size_t> bytes;
  for (int frame = 0; frame < 40; ++frame) {
    const float open = static_cast<float>(scene.camera.shutter_open + frame * 0.25);
    if (frame > 0) animated.set_shutter(open, open + 0.25f);
    animated.render(settings);
    bytes.push_back(device.allocated_bytes());
  }
  std::size_t growths = 0;
  for (std::size_t f = 2; f < bytes.size(); ++f) growths += bytes[f] > bytes[f - 1] ? 1 : 0;
  EXPECT_LE(growths, 4u) << "device buffers grew in " << growths << " of the frames after the second";
  EXPECT_LE(static_cast<double>(bytes.back()), 1.05 * static_cast<double>(bytes[1]))
      << "after 40 frames against after the second";
}

// An emitting mesh placed twice lights the scene twice: the emissive
// light expands over both objects' triangles, exactly the flat path's list.
TEST(RenderInstances, EmissiveLightsExpandPerObject) {
  SceneDescription scene = SceneFiles().load(false);
  Material lamp;
  lamp.name = "lamp";
  lamp.emission = glm::vec3(4.0f);
  scene.materials.push_back(lamp);
  auto panel = std::make_shared<MeshShape>();
  panel->vertices = {{-0.3f, 0, -0.3f}, {0.3f, 0, -0.3f}, {0.3f, 0, 0.3f}, {-0.3f, 0, 0.3f}};
  panel->triangles = {{0, 1, 2}, {0, 2, 3}};
  panel->materials.assign(2, static_cast<std::uint32_t>(scene.materials.size() - 1));
  for (double x : {-1.0, 1.0}) {
    SceneMesh m;
    m.name = "panel";
    m.shape = panel;
    m.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(x, 2.5, 0.0)) *
                  glm::rotate(glm::dmat4(1.0), glm::radians(180.0), glm::dvec3(1, 0, 0));
    scene.meshes.push_back(m);
  }
  Light emissive;
  emissive.shape = LightShape::emissive;
  scene.lights.push_back(emissive);
  std::vector<Light> got = instanced_lights(scene);
  std::vector<Light> want = expand_emissive_lights(scene, flatten(scene));
  ASSERT_EQ(got.size(), want.size());
  ASSERT_EQ(got.size(), scene.lights.size() - 1 + 4) << "two triangles per panel, two panels";
  for (std::size_t l = 0; l < got.size(); ++l) {
    EXPECT_EQ(got[l].position, want[l].position) << l;
    EXPECT_EQ(got[l].edge1, want[l].edge1) << l;
    EXPECT_EQ(got[l].color, want[l].color) << l;
  }
  // A moving emitter is refused, as on the flat path.
  scene.meshes.back().end_transform = glm::translate(glm::dmat4(1.0), glm::dvec3(0.2, 0, 0)) * scene.meshes.back().transform;
  EXPECT_NE(error_of([&] { instanced_lights(scene); }).find("must not move"), std::string::npos);
}

TEST(RenderInstances, OtherStructuresAreRefusedForInstancedScenes) {
  SceneDescription scene = SceneFiles().load(false);
  std::string message = error_of([&] { Renderer r(test_device(), scene, "grid"); });
  EXPECT_NE(message.find("Renderer accel \"grid\""), std::string::npos) << message;
  EXPECT_NE(message.find("BVH family"), std::string::npos) << message;
  EXPECT_NO_THROW(Renderer(test_device(), unshare_meshes(scene), "grid"));
}

TEST(RenderInstances, ForestBuildsOneBunnyAndFitsItsMemoryPlusInstanceRecords) {
  const std::string bunny_path = scene_path("stanford_bunny/bunny.obj");
  SceneDescription forest = builtin_scene("forest", scenes_dir());
  ASSERT_GE(forest.meshes.size(), 10001u);
  Renderer renderer(test_device(), forest, "bvh");
  ASSERT_TRUE(renderer.instanced());
  const SceneStats st = renderer.scene()->stats();
  EXPECT_EQ(st.bottom_levels_built, 2u) << "the bunny and the ground";
  EXPECT_EQ(st.instances, forest.meshes.size());
  // Reference: the bunny alone as a flat BVH and its shading records; each
  // instance may add at most 512 bytes (its trace record, motion, share of
  // the top level and shading record).
  LoadedMesh bunny = load_mesh(bunny_path);
  const std::size_t one_bunny =
      make_accel(test_device(), "bvh", bunny.geometry)->stats().device_bytes + bunny.geometry.triangles.size() * sizeof(ShadeTriangle);
  const std::size_t used = st.device_bytes + renderer.shading_bytes();
  EXPECT_LT(used, one_bunny + forest.meshes.size() * 512) << "device bytes " << used << ", one bunny " << one_bunny;
  // Far below the flat copies' triangles alone.
  EXPECT_LT(used, bunny.geometry.triangles.size() * sizeof(ShadeTriangle) * 20);
  // It renders: some pixels show a bunny (its material), some the ground.
  RenderSettings settings;
  settings.width = 48;
  settings.height = 27;
  std::vector<std::uint32_t> pixels(settings.width * settings.height);
  for (std::uint32_t p = 0; p < pixels.size(); ++p) pixels[p] = p;
  PixelSamples samples = renderer.render_pixels(settings, pixels);
  std::size_t bunnies = std::count(samples.object.begin(), samples.object.end(), 0);
  std::size_t ground = std::count(samples.object.begin(), samples.object.end(), 1);
  EXPECT_GT(bunnies, pixels.size() / 20);
  EXPECT_GT(ground, 0u);
}

TEST(RenderInstances, ForestNeedsTheScenesDirectory) {
  EXPECT_NE(error_of([] { builtin_scene("forest"); }).find("RTCL_SCENES_DIR"), std::string::npos);
  EXPECT_NE(error_of([] { forest_scene("/nonexistent/bunny.obj"); }).find("/nonexistent/bunny.obj"), std::string::npos);
}

TEST(RenderInstancesCli, ForestAndFramesThroughTheCommandLine) {
  TempDir dir;
  expect_usage_error(run_cli(dir, {"render", "--builtin", "forest", "-o", "f.png"}, "RTCL_SCENES_DIR="),
                     "RTCL_SCENES_DIR");
  CliRun forest = run_cli(dir, {"render", "--builtin", "forest", "-o", "f.png", "--width", "64", "--verbose"},
                          "RTCL_SCENES_DIR=" + shell_quoted(scenes_dir()));
  ASSERT_EQ(forest.status, 0) << forest.err;
  EXPECT_NE(forest.out.find("two-level scene: 2 meshes, 10001 instances, 2 bottom levels built"), std::string::npos)
      << forest.out;
  // An animation of a scene file that shares a mesh: one renderer, each
  // later frame re-places the moving objects only.
  SceneFiles files;
  files.load(true);
  CliRun frames = run_cli(files.dir, {"render", files.dir.file("scene.json"), "--frames", "0:2", "-o", "a_%d.png",
                                      "--width", "32", "--verbose"});
  ASSERT_EQ(frames.status, 0) << frames.err;
  EXPECT_EQ(count_of(frames.out, "0 bottom levels built, top level rebuilt"), 2u) << frames.out;
  EXPECT_EQ(count_of(frames.out, "two-level scene:"), 1u) << frames.out;
}

}  // namespace
}  // namespace rtcl::test
