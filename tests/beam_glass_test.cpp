// Refraction beams in the beam renderer (src/rtcl/beam/beam_renderer.*)
// against the ray tracer, whose refraction is exact (Snell per ray): glass of
// index 1 (the linearised transform is then the identity and F = 0, so the
// beam tracer must match as for a diffuse scene), the Cornell box's glass
// block (index 1.5: the linearisation's error, bounded away from edges), a
// right-angle prism whose legs reflect totally (no refracted beam there),
// and the refusal of glossy materials.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "rtcl/beam/beam_renderer.hpp"
#include "rtcl/error.hpp"
#include "rtcl/render/renderer.hpp"
#include "rtcl/scene/scene_file.hpp"
#include "support/cli_run.hpp"
#include "support/error_of.hpp"
#include "support/fixtures.hpp"
#include "support/reference_renderer.hpp"

namespace rtcl::test {
namespace {

SceneDescription cornell_glass() { return load_scene(std::string(RTCL_SOURCE_DIR) + "/scenes/cornell_glass_beam.json"); }

Material& material(SceneDescription& scene, const std::string& name) {
  for (Material& m : scene.materials)
    if (m.name == name) return m;
  throw Error("no material " + name);
}

void clamp_display(Image& image) {
  for (float& c : image.rgb) c = std::min(std::max(c, 0.0f), 1.0f);
}

struct Comparison {
  ImageDifference beam, ray4;  // against the ray tracer at 64 spp
  beam::BeamStats stats;
};

// Beam tracing and the ray tracer at 4 spp against the ray tracer at 64 spp
// (w x w, depth 5), as displayed (clamped to [0, 1]); pixels within one pixel
// of a step over `step` excused in max_error_unmasked.
Comparison compare(const SceneDescription& scene, std::uint32_t w, double step) {
  Comparison c;
  beam::BeamSettings bs;
  bs.width = bs.height = w;
  Image beam_image = beam::render_beam(test_device(), scene, bs, &c.stats);
  Renderer renderer(test_device(), scene, "bvh");
  RenderSettings rs;
  rs.width = rs.height = w;
  rs.spp = 64;
  Image ray64 = renderer.render(rs);
  rs.spp = 4;
  Image ray4 = renderer.render(rs);
  for (Image* im : {&beam_image, &ray64, &ray4}) clamp_display(*im);
  std::vector<std::uint8_t> edges = edge_pixels(ray64, step, 1);
  c.beam = compare_images(beam_image, ray64, edges, 0.02);
  c.ray4 = compare_images(ray4, ray64, edges, 0.02);
  std::printf("%ux%u: %zu reflected, %zu refracted beams, %zu total internal reflections in %u levels; rmse "
              "against 64 spp: beam %.4f, 4 spp %.4f; away from edges (%zu pixels excused) beam max %.5f, 4 spp "
              "max %.5f\n",
              w, w, c.stats.reflected_beams, c.stats.refracted_beams, c.stats.total_internal_reflections,
              c.stats.levels, c.beam.rmse, c.ray4.rmse, c.beam.masked_pixels, c.beam.max_error_unmasked,
              c.ray4.max_error_unmasked);
  return c;
}

TEST(BeamGlass, IndexOneGlassMatchesTheRayTracer) {
  // eta = 1: alpha = 0, so M_t is the identity, and F = 0: the refracted
  // beams see the scene behind the block exactly, weighted kt.
  SceneDescription scene = cornell_glass();
  material(scene, "glass").ior = 1.0f;
  Comparison c = compare(scene, 48, 0.01);
  EXPECT_GT(c.stats.refracted_beams, 0u);
  EXPECT_EQ(c.stats.total_internal_reflections, 0u);
  // As for mirrors (beam_mirror_test.cpp): away from edges the two differ by
  // the shading's curvature over a pixel (1e-2 allowed), and over the whole
  // image exact coverage is at least as close to 64 spp as 4 spp is.
  EXPECT_LT(c.beam.max_error_unmasked, 1e-2);
  EXPECT_LT(c.beam.rmse, c.ray4.rmse);
}

TEST(BeamGlass, GlassBlockMatchesTheRayTracerAwayFromEdges) {
  SceneDescription scene = cornell_glass();
  Comparison c = compare(scene, 48, 0.01);
  EXPECT_GT(c.stats.refracted_beams, 0u);
  EXPECT_GE(c.stats.levels, 3u);  // into the block, out of it, and what lies behind
  // The linearisation is exact for each beam's central ray; the other rays
  // of an 8x8-pixel beam (half-angle 3.3 degrees here, tan 0.057) land off
  // by up to 0.024 (normal incidence) .. 0.07 (50 degrees) of their depth
  // behind the interface (beam_refraction_test.cpp, half-width 0.05), i.e.
  // at most 0.04 x 0.6 (the block's size) = 0.025 scene units, under half a
  // pixel (0.058 units at 48 px): it moves edges seen through the glass,
  // which are excused, and shifts smooth shading by far less than the 1e-2
  // allowed for its curvature. Over the whole image exact coverage still
  // beats 4 spp.
  EXPECT_LT(c.beam.max_error_unmasked, 1e-2);
  EXPECT_LT(c.beam.rmse, c.ray4.rmse);
}

// A right-angle glass prism (index 1.5), its hypotenuse facing the camera:
// rays enter at near-normal incidence, meet each leg at about 45 degrees,
// beyond the critical angle asin(1 / 1.5) = 41.8 degrees, and come back out
// of the hypotenuse (a retroreflector) to a lit wall behind the camera.
SceneDescription prism_scene() {
  SceneDescription scene;
  scene.source = "prism";
  scene.camera.position = {0.0f, 0.0f, 5.0f};
  scene.camera.look_at = {0.0f, 0.0f, 0.0f};
  scene.camera.fov_deg = 6.0f;
  scene.ambient = glm::vec3(0.05f);
  scene.background = {0.1f, 0.2f, 0.3f};
  scene.lights.push_back(PointLight{glm::vec3(1.0f, 1.5f, 7.0f), glm::vec3(1.0f), 1.0f});
  Material glass;
  glass.name = "glass";
  glass.diffuse = glm::vec3(0.0f);
  glass.kt = glm::vec3(1.0f);
  glass.ior = 1.5f;
  Material wall;
  wall.name = "wall";
  wall.diffuse = {0.7f, 0.5f, 0.3f};
  wall.ambient = glm::vec3(1.0f);
  scene.materials = {glass, wall};
  SceneMesh mesh;
  mesh.name = "prism and wall";
  MeshShape& m = mesh.edit_shape();
  const float a = 1.2f;
  // Prism: hypotenuse z = 0, apex edge at z = -a, y in [-a, a].
  m.vertices = {{-a, -a, 0}, {a, -a, 0}, {0, -a, -a}, {-a, a, 0}, {a, a, 0}, {0, a, -a},
                // wall z = 9 facing the prism
                {-8, -8, 9}, {8, -8, 9}, {8, 8, 9}, {-8, 8, 9}};
  // Counter-clockwise seen from outside (outward normals).
  m.triangles = {{0, 1, 4}, {0, 4, 3},  // hypotenuse, +z
                 {0, 3, 5}, {0, 5, 2},  // leg x < 0
                 {1, 2, 5}, {1, 5, 4},  // leg x > 0
                 {0, 2, 1}, {3, 4, 5},  // caps
                 {6, 8, 7}, {6, 9, 8}};  // wall, normal -z
  m.materials = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1};
  scene.meshes.push_back(mesh);
  return scene;
}

TEST(BeamGlass, TotalInternalReflectionInAPrism) {
  SceneDescription scene = prism_scene();
  Comparison c = compare(scene, 32, 0.01);
  // Every beam that meets a leg from inside is totally reflected: no
  // refracted beam leaves there, and its whole weight kt goes to the
  // reflected beam (F = 1). Beams enter and leave through the hypotenuse.
  EXPECT_GT(c.stats.total_internal_reflections, 0u);
  EXPECT_GE(c.stats.levels, 5u);  // hypotenuse, leg, leg, hypotenuse, wall
  // Near-normal incidence on the hypotenuse (field of view 6 degrees: the
  // rays meet the legs at 45 +- 3 degrees, all beyond the critical angle), so the
  // linearisation's error is tiny; 1e-2 as for smooth shading elsewhere. A
  // lost reflected weight would show the background instead of the wall.
  EXPECT_LT(c.beam.max_error_unmasked, 1e-2);
  EXPECT_LT(c.beam.rmse, 1e-2);
}

// A glass slab (z in [-0.1, 0.1], index 1.5, kt 0.9) before an emitting wall
// (radiance 1), seen head-on through a 2-degree field of view: every pixel's
// radiance is a closed form of the weights.
TEST(BeamGlass, SlabWeightsAreTheFresnelSeries) {
  SceneDescription scene;
  scene.source = "slab";
  scene.camera.position = {0.0f, 0.0f, 5.0f};
  scene.camera.look_at = {0.0f, 0.0f, 0.0f};
  scene.camera.fov_deg = 2.0f;
  scene.ambient = glm::vec3(0.0f);
  scene.background = glm::vec3(0.0f);
  Material glass;
  glass.name = "glass";
  glass.diffuse = glm::vec3(0.0f);
  glass.kt = glm::vec3(0.9f);
  glass.ior = 1.5f;
  Material wall;
  wall.name = "wall";
  wall.diffuse = glm::vec3(0.0f);
  wall.emission = glm::vec3(1.0f);
  scene.materials = {glass, wall};
  SceneMesh mesh;
  mesh.name = "slab and wall";
  MeshShape& m = mesh.edit_shape();
  m.vertices = {{-10, -10, 0.1f}, {10, -10, 0.1f}, {10, 10, 0.1f}, {-10, 10, 0.1f},
                {-10, -10, -0.1f}, {10, -10, -0.1f}, {10, 10, -0.1f}, {-10, 10, -0.1f},
                {-10, -10, -5}, {10, -10, -5}, {10, 10, -5}, {-10, 10, -5}};
  m.triangles = {{0, 1, 2}, {0, 2, 3},     // front face, normal +z
                 {4, 6, 5}, {4, 7, 6},     // back face, normal -z (outward)
                 {8, 9, 10}, {8, 10, 11}};  // wall, facing the slab
  m.materials = {0, 0, 0, 0, 1, 1};
  scene.meshes.push_back(mesh);
  beam::BeamSettings bs;
  bs.width = bs.height = 16;
  bs.min_weight = 1e-4f;  // the second term's beams weigh 9.7e-4
  beam::BeamStats st;
  Image image = beam::render_beam(test_device(), scene, bs, &st);
  // Normal incidence: F = ((1.5 - 1) / (1.5 + 1))^2 = 0.04 entering and
  // leaving. Through: kt (1 - F) twice. Reflected inside at the back face
  // and again at the front (kt F each), then through: one more term, at
  // depth 4; the next needs depth 6 > 5. The rays are at most 1.4 degrees
  // off the axis, where F differs from 0.04 by under 1e-4 relative.
  const double F = 0.04, kt = 0.9, through = kt * (1.0 - F) * kt * (1.0 - F);
  const double want = through * (1.0 + (kt * F) * (kt * F));
  for (std::size_t i = 0; i < image.rgb.size(); ++i) EXPECT_NEAR(image.rgb[i], want, 1e-4 * want) << i;
  EXPECT_EQ(st.total_internal_reflections, 0u);
  EXPECT_GT(st.refracted_beams, 0u);
  // Without the second term (depth 3) the image is darker by exactly it.
  bs.max_depth = 3;
  Image shallow = beam::render_beam(test_device(), scene, bs);
  for (std::size_t i = 0; i < shallow.rgb.size(); ++i) EXPECT_NEAR(shallow.rgb[i], through, 1e-4 * through) << i;
}

TEST(BeamGlass, CommandLine) {
  TempDir dir;
  const std::string scenes = std::string(RTCL_SOURCE_DIR) + "/scenes/";
  CliRun ok = run_cli(dir, {"render", scenes + "cornell_glass_beam.json", "--method", "beam", "-o", "glass.png",
                            "--width", "24"});
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_NE(ok.out.find("refraction linearised, one M_t per beam"), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find("refracted beams"), std::string::npos) << ok.out;
  // A glossy glass: one message naming the scene and the material, exit 1, no image.
  const std::string glossy = dir.write(
      "glossy.json", "{\"camera\": {\"position\": [0, 1, 3.9], \"look_at\": [0, 1, 0]},\n"
                     " \"lights\": [{\"position\": [0, 1.9, 0]}],\n"
                     " \"materials\": {\"frosted\": {\"kt\": 0.9, \"roughness\": 0.3}},\n"
                     " \"objects\": [{\"type\": \"mesh\", \"file\": \"" + scenes + "glass_block.obj\", "
                     "\"material\": \"frosted\"}]}\n");
  expect_failure(run_cli(dir, {"render", glossy, "--method", "beam", "-o", "g.png", "--width", "16"}),
                 "glossy.json: material 'frosted' is glossy; --method beam traces mirror reflection and refraction "
                 "only (use --method ray)",
                 dir, "g.png");
}

TEST(BeamGlass, GlossyMaterialsAreRefused) {
  SceneDescription scene = cornell_glass();
  material(scene, "glass").roughness = 0.2f;
  std::string e = error_of([&] { beam::check_beam_scene(scene); });
  EXPECT_NE(e.find("cornell_glass_beam.json: material 'glass' is glossy; --method beam traces mirror reflection and "
                   "refraction only"),
            std::string::npos)
      << e;
}

}  // namespace
}  // namespace rtcl::test
