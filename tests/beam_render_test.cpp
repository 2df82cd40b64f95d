// `rtcl render --method beam` (src/rtcl/beam/beam_renderer.*): the device
// walk's pixel coverage against an exact coverage reference computed without
// beams, the image against the ray tracer at 64 spp, and the refusals.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "rtcl/beam/beam_renderer.hpp"
#include "rtcl/beam/polygon2d.hpp"
#include "rtcl/beam/screen_space.hpp"
#include "rtcl/error.hpp"
#include "rtcl/render/camera.hpp"
#include "rtcl/render/renderer.hpp"
#include "rtcl/scene/scene_file.hpp"
#include "support/cli_run.hpp"
#include "support/error_of.hpp"
#include "support/fixtures.hpp"
#include "support/reference_renderer.hpp"

namespace rtcl::test {
namespace {

SceneDescription cornell() { return load_scene(std::string(RTCL_SOURCE_DIR) + "/scenes/cornell_beam.json"); }

// Exact coverage without beams, tiles or walks: triangle P is visible where
// its projection lies and no other triangle Q is nearer, i.e. P minus every
// Q clipped to the half-plane where Q's plane is nearer (polygon2d in
// double, tested on its own in polygon2d_test.cpp).
std::map<std::pair<std::uint32_t, std::uint32_t>, double> reference_coverage(const SceneDescription& scene, std::uint32_t w,
                                                                             std::uint32_t h) {
  FlatScene flat = flatten(scene);
  beam::ScreenSpace screen = beam::screen_space(camera_frame(scene.camera, w, h), w, h, flat.geometry);
  std::vector<beam::ScreenPolygon> polys = beam::screen_polygons(screen, flat.geometry);
  std::map<std::pair<std::uint32_t, std::uint32_t>, double> out;
  const double min_area = 1e-12;
  for (const beam::ScreenPolygon& p : polys) {
    beam::Region vis{beam::Convex{p.v}};
    for (const beam::ScreenPolygon& q : polys) {
      if (&q == &p) continue;
      glm::dvec3 d = q.inv_depth - p.inv_depth;
      beam::Convex front = beam::clip(beam::Convex{q.v}, beam::HalfPlane{d.x, d.y, d.z});
      if (front.v.size() >= 3) vis = beam::subtract(vis, front, min_area);
    }
    for (const beam::Convex& c : vis)
      for (std::uint32_t y = 0; y < h; ++y)
        for (std::uint32_t x = 0; x < w; ++x) {
          beam::Convex part = beam::intersect(c, beam::rectangle(x, y, x + 1.0, y + 1.0));
          if (part.v.size() >= 3) out[{y * w + x, p.prim}] += beam::signed_area(part.v);
        }
  }
  return out;
}

TEST(BeamRender, CoverageMatchesExactReference) {
  SceneDescription scene = cornell();
  const std::uint32_t w = 40, h = 40;
  auto want = reference_coverage(scene, w, h);
  beam::BeamSettings s;
  s.width = w;
  s.height = h;
  std::map<std::pair<std::uint32_t, std::uint32_t>, double> got;
  for (const beam::CoverageEntry& e : beam::beam_coverage(test_device(), scene, s)) got[{e.pixel, e.prim}] += e.area;
  // The device drops pieces below 1e-6 of the 64 px^2 tile (6.4e-5 px^2)
  // and rounds tile-local float coordinates (about 5e-7 px per vertex): a
  // few of either per pixel stay far below 1e-3 of the pixel.
  std::map<std::pair<std::uint32_t, std::uint32_t>, double> diff = want;
  for (const auto& [k, a] : got) diff[k] -= a;
  double worst = 0.0;
  for (const auto& [k, d] : diff) worst = std::max(worst, std::abs(d));
  EXPECT_LT(worst, 1e-3);
  // No pixel is covered more than once; the box fills most of the view.
  std::vector<double> per_pixel(w * h, 0.0);
  for (const auto& [k, a] : got) per_pixel[k.first] += a;
  for (double a : per_pixel) EXPECT_LE(a, 1.0 + 1e-3);
  EXPECT_GT(std::count_if(per_pixel.begin(), per_pixel.end(), [](double a) { return a > 1.0 - 1e-3; }), w * h / 2);
}

TEST(BeamRender, DiffuseSceneMatchesRayTracerAt64Spp) {
  SceneDescription scene = cornell();
  const std::uint32_t w = 48, h = 48;
  beam::BeamSettings bs;
  bs.width = w;
  bs.height = h;
  Image beam_image = beam::render_beam(test_device(), scene, bs);
  Renderer renderer(test_device(), scene, "bvh");
  RenderSettings rs;
  rs.width = w;
  rs.height = h;
  rs.spp = 64;
  Image ray_image = renderer.render(rs);
  // Where both see one surface lit the same way the two agree to float
  // rounding; they differ at visibility edges (64 stratified samples
  // estimate a pixel's coverage by an edge to about 1/16 of it, times the
  // contrast) and at shadow edges (the beam tracer shades a fragment's
  // share of a pixel at one point, hard; the ray tracer at 64 points). Those
  // are the pixels within one pixel of an edge: a few hundred of 2304.
  std::vector<std::uint8_t> edges = edge_pixels(ray_image, 0.05, 1);
  ImageDifference d = compare_images(beam_image, ray_image, edges, 0.02);
  std::printf("beam vs ray tracer at 64 spp, %ux%u: rmse %.4f, max %.4f; away from edges (%zu pixels excused) max "
              "%.5f\n", w, h, d.rmse, d.max_error, d.masked_pixels, d.max_error_unmasked);
  // Away from edges both average the same smooth shading over the pixel,
  // the beam tracer by its value at the coverage centroid: they differ by
  // the shading's curvature over a pixel (a pixel here spans about 0.04
  // scene units, 0.04 of the distance to the light: a few 1e-3 of the
  // radiance), allowed 1e-2.
  EXPECT_LT(d.max_error_unmasked, 1e-2);
  EXPECT_LT(d.rmse, 0.05);
  EXPECT_LT(d.masked_pixels, std::size_t(w) * h * 3 / 4);
}

TEST(BeamRender, RefusesSpheresAndAreaLights) {
  SceneDescription scene = cornell();
  scene.spheres.push_back({});
  try {
    beam::check_beam_scene(scene);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("1 sphere(s)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cornell_beam.json"), std::string::npos) << e.what();
  }
  scene = cornell();
  scene.lights[0].shape = LightShape::quad;
  EXPECT_THROW(beam::check_beam_scene(scene), Error);
}

TEST(BeamRender, CommandLine) {
  TempDir dir;
  const std::string scenes = std::string(RTCL_SOURCE_DIR) + "/scenes/";
  CliRun ok = run_cli(dir, {"render", scenes + "cornell_beam.json", "--method", "beam", "-o", "beam.png", "--width", "16"});
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_NE(ok.out.find("beam tracing, exact depth order"), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find("reflection and refraction beams to depth 5"), std::string::npos) << ok.out;
  expect_failure(run_cli(dir, {"render", scenes + "cornell.json", "--method", "beam", "-o", "s.png", "--width", "16"}),
                 "--method beam traces polygons only, and the scene has 2 sphere(s)", dir, "s.png");
  expect_failure(run_cli(dir, {"render", scenes + "cornell_beam.json", "--method", "beam", "--frames", "0:1", "-o",
                                "f%d.png", "--width", "16"}),
                 "--frames: not with --method beam", dir, "f0.png", 2);
  expect_usage_error(run_cli(dir, {"render", "--method", "cone", "-o", "x.png"}), "--method");
  expect_usage_error(run_cli(dir, {"render", "--method", "beam", "--beam-order", "random", "-o", "x.png"}),
                     "--beam-order");
}

TEST(BeamRender, MovingObjectsAreRefused) {
  SceneDescription scene = load_scene(std::string(RTCL_SOURCE_DIR) + "/scenes/cornell_beam.json");
  ASSERT_FALSE(scene.meshes.empty());
  scene.meshes[0].end_transform = glm::translate(glm::dmat4(1.0), glm::dvec3(0.1, 0.0, 0.0));
  scene.meshes[0].motion_key = "moving.json: objects[0].motion";
  EXPECT_NE(error_of([&] { beam::check_beam_scene(scene); }).find("moving.json: objects[0].motion: a moving object"),
            std::string::npos);
}

}  // namespace
}  // namespace rtcl::test
