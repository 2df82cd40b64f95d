// The BVH frustum cull of beam candidates (src/rtcl/beam/beam_cull.*)
// against the exact test it fronts: every triangle whose screen polygon in a
// beam's world meets the beam's cross-section with positive area (polygon2d
// in double, over all triangles) must survive the cull, in the viewing
// world, a mirrored world, a refracted (sheared) world and one refracted
// then mirrored, at scene scales
// 1e-3, 1 and 1e3; and the renderer's candidates with the cull equal those
// without it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "rtcl/accel/bvh.hpp"
#include "rtcl/beam/beam_cull.hpp"
#include "rtcl/beam/beam_renderer.hpp"
#include "rtcl/beam/mirror.hpp"
#include "rtcl/beam/polygon2d.hpp"
#include "rtcl/beam/refraction.hpp"
#include "rtcl/beam/screen_space.hpp"
#include "rtcl/render/camera.hpp"
#include "rtcl/scene/scene_file.hpp"
#include "support/fixtures.hpp"
#include "support/reference_renderer.hpp"

namespace rtcl::test {
namespace {

using glm::dvec2;
using glm::dvec3;
using glm::dvec4;

struct VirtualWorld {
  const char* name;
  glm::dmat4 to_virtual;
  bool clipped;
  dvec4 keep;
};

// A random convex cross-section inside the screen: a rectangle or a triangle
// of 1 .. w/2 pixels.
beam::Convex random_section(std::mt19937& rng, double w, double h) {
  std::uniform_real_distribution<double> x(0.0, w), y(0.0, h), size(1.0, w / 2);
  double x0 = x(rng), y0 = y(rng), s = size(rng);
  if (rng() % 2) return beam::rectangle(x0, y0, std::min(w, x0 + s), std::min(h, y0 + s));
  return beam::make_convex({{x0, y0}, {std::min(w, x0 + s), y0}, {x0, std::min(h, y0 + s)}});
}

// Checks the cull against the exact candidates of `sections` beams in each
// world; returns (culled, exact) totals.
std::pair<std::size_t, std::size_t> check_cull(const Geometry& g, const beam::ScreenSpace& screen,
                                               const std::vector<VirtualWorld>& worlds, std::mt19937& rng, int sections) {
  BuildTree bvh = build_binary_bvh(g);
  std::size_t culled_total = 0, exact_total = 0;
  for (const VirtualWorld& w : worlds)
    for (int i = 0; i < sections; ++i) {
      beam::Convex section = random_section(rng, screen.width, screen.height);
      std::vector<std::uint32_t> culled;
      beam::cull(bvh, beam::beam_frustum(screen, section, w.to_virtual, w.clipped ? &w.keep : nullptr), culled);
      std::set<std::uint32_t> kept(culled.begin(), culled.end());
      EXPECT_EQ(kept.size(), culled.size()) << "a triangle listed twice";
      const double min_area = beam::beam_min_area_fraction * beam::signed_area(section.v);
      for (std::uint32_t t = 0; t < g.triangles.size(); ++t) {
        beam::ScreenPolygon sp;
        if (!beam::screen_polygon(screen, g, t, w.to_virtual, w.clipped ? &w.keep : nullptr, 0.0, &sp)) continue;
        beam::Convex part = beam::intersect(beam::Convex{sp.v}, section);
        if (part.v.size() < 3 || beam::signed_area(part.v) < min_area) continue;
        ++exact_total;
        EXPECT_TRUE(kept.count(t)) << w.name << ": triangle " << t << " meets beam " << i << " but was culled";
      }
      culled_total += culled.size();
    }
  return {culled_total, exact_total};
}

std::vector<VirtualWorld> worlds_of(const beam::ScreenSpace& screen, const Geometry& g, std::uint32_t mirror_prim,
                             std::uint32_t glass_prim) {
  auto plane = [&](std::uint32_t t) {
    return beam::plane_through(dvec3(g.vertices[g.triangles[t].x]), dvec3(g.vertices[g.triangles[t].y]),
                               dvec3(g.vertices[g.triangles[t].z]));
  };
  auto far_side = [&](dvec4 L) { return glm::dot(L, dvec4(screen.frame.origin, 1.0)) > 0.0 ? -L : L; };
  dvec4 mirror = plane(mirror_prim), glass = plane(glass_prim);
  const glm::uvec3& t = g.triangles[glass_prim];
  dvec3 centre = (dvec3(g.vertices[t.x]) + dvec3(g.vertices[t.y]) + dvec3(g.vertices[t.z])) / 3.0;
  glm::dmat4 bend = *beam::refraction_matrix(glass, centre - screen.frame.origin, 1.0 / 1.5);
  // Refracted, then mirrored: the mirror plane seen in the refracted world
  // is L' with L' . (bend p) = L . p.
  glm::dmat4 both = bend * beam::reflection_matrix(mirror);
  dvec4 mirror_seen = glm::transpose(glm::inverse(bend)) * mirror;
  mirror_seen /= glm::length(dvec3(mirror_seen));
  return {{"viewing", glm::dmat4(1.0), false, dvec4(0.0)},
          {"mirrored", beam::reflection_matrix(mirror), true, far_side(mirror)},
          {"refracted", bend, true, far_side(glass)},
          {"refracted, then mirrored", both, true, far_side(mirror_seen)}};
}

TEST(BeamCull, KeepsEveryExactCandidateOnTheCornellBox) {
  SceneDescription scene = load_scene(RTCL_SOURCE_DIR "/scenes/cornell_glass_beam.json");
  FlatScene flat = flatten(scene);
  const Geometry& g = flat.geometry;
  beam::ScreenSpace screen = beam::screen_space(camera_frame(scene.camera, 64, 64), 64, 64, g);
  auto prim_of = [&](const char* material) {
    for (std::uint32_t t = 0; t < g.triangles.size(); ++t)
      if (scene.materials[flat.material[t]].name == material) return t;
    return 0u;
  };
  std::mt19937 rng(13);
  auto worlds = worlds_of(screen, g, prim_of("mirror"), prim_of("glass"));
  auto [culled, exact] = check_cull(g, screen, worlds, rng, 150);
  std::printf("cornell: %zu culled candidates, %zu exact, of %zu\n", culled, exact, 600 * g.triangles.size());
  EXPECT_GT(exact, 0u);
  // The cull must prune: fewer than half of all (beam, triangle) pairs.
  EXPECT_LT(culled, 600 * g.triangles.size() / 2);
}

TEST(BeamCull, KeepsEveryExactCandidateOfATriangleSoupAtAnyScale) {
  for (double scale : {1e-3, 1.0, 1e3}) {
    std::mt19937 rng(29);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), e(-0.2f, 0.2f);
    Geometry g;
    for (int i = 0; i < 400; ++i) {
      glm::vec3 c(u(rng), u(rng), u(rng));
      for (int k = 0; k < 3; ++k)
        g.vertices.push_back(float(scale) * (c + glm::vec3(e(rng), e(rng), e(rng))));
      g.triangles.push_back(glm::uvec3(3 * i, 3 * i + 1, 3 * i + 2));
    }
    Camera cam;
    cam.position = glm::vec3(0.3f, 0.2f, 2.5f) * float(scale);
    cam.look_at = glm::vec3(0.0f);
    cam.fov_deg = 50.0f;
    beam::ScreenSpace screen = beam::screen_space(camera_frame(cam, 48, 40), 48, 40, g);
    auto worlds = worlds_of(screen, g, 7, 11);
    auto [culled, exact] = check_cull(g, screen, worlds, rng, 60);
    EXPECT_GT(exact, 0u) << scale;
    EXPECT_LT(culled, 240 * g.triangles.size()) << scale;
  }
}

TEST(BeamCull, RendererCandidatesEqualThoseOfAllTriangles) {
  SceneDescription scene = load_scene(RTCL_SOURCE_DIR "/scenes/cornell_glass_beam.json");
  beam::BeamSettings s;
  s.width = s.height = 32;
  beam::BeamStats with, without;
  Image a = beam::render_beam(test_device(), scene, s, &with);
  s.cull = beam::CandidateCull::all;
  Image b = beam::render_beam(test_device(), scene, s, &without);
  EXPECT_GT(with.reflected_beams + with.refracted_beams, 0u);
  EXPECT_EQ(with.candidates, without.candidates);
  EXPECT_EQ(with.fragments, without.fragments);
  EXPECT_EQ(with.reflected_beams, without.reflected_beams);
  EXPECT_EQ(with.refracted_beams, without.refracted_beams);
  // The same candidates in the same order (ties by triangle id): the same
  // fragments, the same image.
  EXPECT_EQ(compare_images(a, b).max_error, 0.0);
}

}  // namespace
}  // namespace rtcl::test
