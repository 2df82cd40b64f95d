// Reflection beams (src/rtcl/beam/mirror.*, beam_renderer.*): the lecture's
// M_r against closed forms, and a mirror scene against the ray tracer at 64
// spp at several beam-tree depths.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <string>
#include <utility>

#include "rtcl/beam/beam_renderer.hpp"
#include "rtcl/beam/mirror.hpp"
#include "rtcl/error.hpp"
#include "rtcl/render/renderer.hpp"
#include "rtcl/scene/scene_file.hpp"
#include "support/fixtures.hpp"
#include "support/reference_renderer.hpp"

namespace rtcl::test {
namespace {

using glm::dvec3;
using glm::dvec4;

TEST(BeamMirror, ReflectionIsAnInvolutionFixingItsPlane) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (double scale : {1e-4, 1.0, 1e5}) {
    for (int i = 0; i < 20; ++i) {
      dvec3 a = scale * dvec3(u(rng), u(rng), u(rng)), b = scale * dvec3(u(rng), u(rng), u(rng)),
            c = scale * dvec3(u(rng), u(rng), u(rng));
      dvec4 L = beam::plane_through(a, b, c);
      glm::dmat4 m = beam::reflection_matrix(L);
      glm::dmat4 mm = m * m;
      for (int r = 0; r < 4; ++r)
        for (int col = 0; col < 4; ++col)
          EXPECT_NEAR(mm[col][r], r == col ? 1.0 : 0.0, (col == 3 && r < 3 ? scale : 1.0) * 1e-13);
      // Points of the plane stay; a point at distance d goes to distance -d
      // along the normal; the linear part is orthogonal with determinant -1.
      for (const dvec3& p : {a, b, c}) EXPECT_LT(glm::length(dvec3(m * dvec4(p, 1.0)) - p), 1e-14 * scale * 8);
      dvec3 n(L), q = a + 0.3 * scale * n + 0.2 * (b - a);
      dvec3 image = dvec3(m * dvec4(q, 1.0));
      EXPECT_NEAR(glm::dot(dvec4(image, 1.0), L), -0.3 * scale, 1e-13 * scale * 8);
      EXPECT_NEAR(glm::determinant(glm::dmat3(m)), -1.0, 1e-13);
    }
  }
  // The lecture's closed form for the plane z = 1: (x, y, z) -> (x, y, 2 - z).
  glm::dmat4 m = beam::reflection_matrix(dvec4(0, 0, 1, -1));
  dvec4 p = m * dvec4(0.25, -3.0, 5.0, 1.0);
  EXPECT_DOUBLE_EQ(p.x, 0.25);
  EXPECT_DOUBLE_EQ(p.y, -3.0);
  EXPECT_DOUBLE_EQ(p.z, -3.0);
  EXPECT_DOUBLE_EQ(p.w, 1.0);
  // A non-unit normal is normalised: 2x = 4 is the plane x = 2.
  dvec4 q = beam::reflection_matrix(dvec4(2, 0, 0, -4)) * dvec4(3.0, 1.0, 1.0, 1.0);
  EXPECT_NEAR(q.x, 1.0, 1e-15);
  EXPECT_THROW(beam::reflection_matrix(dvec4(0, 0, 0, 1)), Error);
  EXPECT_THROW(beam::plane_through(dvec3(0), dvec3(1), dvec3(2)), Error);
}

TEST(BeamMirror, MirrorSceneMatchesRayTracerAt64Spp) {
  SceneDescription scene = load_scene(std::string(RTCL_SOURCE_DIR) + "/scenes/cornell_mirror_beam.json");
  // The floor a mirror too (the mesh's first two triangles): with the
  // mirror wall it makes a corner reflector, whose beams reach the second
  // and third levels (worlds of two and three M_r).
  std::uint32_t mirror = 0;
  while (scene.materials[mirror].name != "green_mirror") ++mirror;  // no highlight: see below
  MeshShape& room = scene.meshes[0].edit_shape();
  room.materials[0] = room.materials[1] = mirror;
  Renderer renderer(test_device(), scene, "bvh");
  for (auto [w, depth] : {std::pair<std::uint32_t, std::uint32_t>{48, 0}, {48, 1}, {48, 5}}) {
    const std::uint32_t h = w;
    beam::BeamSettings bs;
    bs.width = w;
    bs.height = h;
    bs.max_depth = depth;
    beam::BeamStats st;
    Image beam_image = beam::render_beam(test_device(), scene, bs, &st);
    RenderSettings rs;
    rs.width = w;
    rs.height = h;
    rs.spp = 64;
    rs.max_depth = depth;
    Image ray_image = renderer.render(rs);
    rs.spp = 4;
    Image ray4 = renderer.render(rs);
    // Compared as displayed (clamped to [0, 1]): the lamp's radiance (17)
    // would weigh its outline above everything else.
    for (Image* im : {&beam_image, &ray_image, &ray4})
      for (float& c : im->rgb) c = std::min(std::max(c, 0.0f), 1.0f);
    // Away from edges (any step over 0.01 within a pixel: this scene's dark
    // mirrors have low-contrast shadow edges) both average the same smooth
    // shading over the pixel; they differ by its curvature (1e-2 allowed, as
    // in beam_render_test.cpp). Over the whole image the beam tracer's exact
    // coverage must be at least as close to 64 spp as 4 spp ray tracing is.
    ImageDifference d = compare_images(beam_image, ray_image, edge_pixels(ray_image, 0.01, 1), 0.02);
    double rmse4 = compare_images(ray4, ray_image).rmse;
    std::printf("%ux%u depth %u: %zu reflected beams in %u levels; rmse against 64 spp: beam %.4f, 4 spp %.4f; away "
                "from edges max %.5f (%zu pixels excused)\n",
                w, h, depth, st.reflected_beams, st.levels, d.rmse, rmse4, d.max_error_unmasked, d.masked_pixels);
    EXPECT_LT(d.max_error_unmasked, 1e-2) << depth;
    EXPECT_LT(d.rmse, rmse4) << depth;
    EXPECT_EQ(st.reflected_beams > 0, depth > 0);
    EXPECT_LE(st.levels, depth + 1);
    if (depth == 5) EXPECT_GE(st.levels, 3u);
  }
}

}  // namespace
}  // namespace rtcl::test
