// The routines the host reference renderer (support/reference_renderer.cpp)
// shares with the device renderer, each against its closed form, so that a
// fault in one cannot hide by being the same on both sides: the camera's
// rays (camera_frame), the world-space primitives of a scene (flatten), the
// scene at a time of its motion (scene_at), emissive triangles as lights
// (expand_emissive_lights), the lens and time samples and the orthonormal
// basis of kernels/shared/sampling.h and orthonormal_basis.hpp. (The
// pixel samplers, permutations and filters: sampling_test.cpp.)
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "rtcl/render/camera.hpp"
#include "rtcl/render/render_layouts.hpp"
#include "rtcl/scene/motion.hpp"
#include "rtcl/scene/orthonormal_basis.hpp"
#include "rtcl/scene/scene_description.hpp"

namespace rtcl::test {
namespace {

void expect_near(const glm::dvec3& got, const glm::dvec3& want, double tolerance, const char* what) {
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], tolerance) << what << " [" << k << "]";
}

// The direction through image position (x, y), scaled to a unit step along
// the view direction.
glm::dvec3 ray_through(const CameraFrame& f, double x, double y) { return f.corner + x * f.du + y * f.dv; }

TEST(RenderInputs, CameraRaysThroughTheCornersAndCentre) {
  // Looking down -z from (0, 0, 5) with a 90 degree vertical field: the
  // image plane at distance 1 spans y in [-1, 1] and, for a 4 x 2 image,
  // x in [-2, 2].
  Camera c;
  c.position = {0.0f, 0.0f, 5.0f};
  c.look_at = {0.0f, 0.0f, 0.0f};
  c.up = {0.0f, 1.0f, 0.0f};
  c.fov_deg = 90.0f;
  CameraFrame f = camera_frame(c, 4, 2);
  expect_near(f.origin, {0, 0, 5}, 0.0, "origin");
  expect_near(ray_through(f, 0, 0), {-2, 1, -1}, 1e-12, "top-left corner");
  expect_near(ray_through(f, 4, 0), {2, 1, -1}, 1e-12, "top-right corner");
  expect_near(ray_through(f, 4, 2), {2, -1, -1}, 1e-12, "bottom-right corner");
  expect_near(ray_through(f, 2, 1), {0, 0, -1}, 1e-12, "centre");
  expect_near(ray_through(f, 0.5, 0.5), {-1.5, 0.5, -1}, 1e-12, "centre of the top-left pixel");

  // Looking along +x with z up and a 60 degree field, square image: left is
  // +y, and the plane at distance 1 spans tan(30 deg) = 1/sqrt(3) each way.
  c.position = {1.0f, 2.0f, 3.0f};
  c.look_at = {11.0f, 2.0f, 3.0f};
  c.up = {0.0f, 0.0f, 1.0f};
  c.fov_deg = 60.0f;
  f = camera_frame(c, 2, 2);
  const double h = 1.0 / std::sqrt(3.0);
  expect_near(f.origin, {1, 2, 3}, 0.0, "origin");
  expect_near(ray_through(f, 0, 0), {1, h, h}, 1e-7, "top-left corner");
  expect_near(ray_through(f, 2, 2), {1, -h, -h}, 1e-7, "bottom-right corner");
  expect_near(ray_through(f, 1, 1), {1, 0, 0}, 1e-12, "centre");

  c.aspect = 2.0f;
  EXPECT_EQ(default_height(c, 8), 4u);
  c.aspect = 0.0f;
  EXPECT_EQ(default_height(c, 8), 8u);
}

SceneMesh unit_cube(glm::dmat4 transform) {
  SceneMesh m;
  m.name = "cube";
  MeshShape& shape = m.edit_shape();
  for (int i = 0; i < 8; ++i) shape.vertices.push_back({i & 1 ? 1.0f : 0.0f, i & 2 ? 1.0f : 0.0f, i & 4 ? 1.0f : 0.0f});
  const unsigned quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) {
    shape.triangles.push_back({q[0], q[1], q[2]});
    shape.triangles.push_back({q[0], q[2], q[3]});
  }
  shape.materials.assign(shape.triangles.size(), 0);
  m.transform = transform;
  return m;
}

SceneDescription one_mesh_scene(const SceneMesh& mesh) {
  SceneDescription s;
  s.materials = {Material{}};
  s.meshes = {mesh};
  return s;
}

// Outward normals of a closed mesh sum, weighted by area, to a signed
// volume: 6 V = sum over triangles of a . (b x c).
double signed_volume(const Geometry& g) {
  double six_v = 0.0;
  for (const glm::uvec3& t : g.triangles)
    six_v += glm::dot(glm::dvec3(g.vertices[t.x]), glm::cross(glm::dvec3(g.vertices[t.y]), glm::dvec3(g.vertices[t.z])));
  return six_v / 6.0;
}

TEST(RenderInputs, FlattenPlacesATransformedCubeAndKeepsItsFacesOutward) {
  // Scale by (2, 3, 4), rotate 90 degrees about z, translate by (10, 0, -1):
  // corner (x, y, z) lands at (10 - 3y, 2x, 4z - 1).
  glm::dmat4 t = glm::translate(glm::dmat4(1.0), glm::dvec3(10, 0, -1)) *
                 glm::rotate(glm::dmat4(1.0), std::numbers::pi / 2, glm::dvec3(0, 0, 1)) *
                 glm::scale(glm::dmat4(1.0), glm::dvec3(2, 3, 4));
  SceneDescription s = one_mesh_scene(unit_cube(t));
  s.spheres.push_back(SceneSphere::still({1.0, 2.0, 3.0}, 0.5, 0));
  FlatScene flat = flatten(s);
  ASSERT_EQ(flat.geometry.vertices.size(), 8u);
  for (int i = 0; i < 8; ++i) {
    double x = i & 1, y = (i >> 1) & 1, z = (i >> 2) & 1;
    expect_near(glm::dvec3(flat.geometry.vertices[i]), {10 - 3 * y, 2 * x, 4 * z - 1}, 1e-5, "corner");
  }
  EXPECT_NEAR(signed_volume(flat.geometry), 24.0, 1e-4) << "outward faces: positive volume 2 x 3 x 4";
  ASSERT_EQ(flat.geometry.spheres.size(), 1u);
  EXPECT_EQ(flat.geometry.spheres[0].center, glm::vec3(1, 2, 3));
  EXPECT_EQ(flat.geometry.spheres[0].radius, 0.5f);
  EXPECT_EQ(flat.material.size(), 13u);

  // A mirror (x -> -x) keeps the faces outward: the corners swap winding.
  FlatScene mirrored = flatten(one_mesh_scene(unit_cube(glm::scale(glm::dmat4(1.0), glm::dvec3(-1, 1, 1)))));
  for (int i = 0; i < 8; ++i) EXPECT_EQ(mirrored.geometry.vertices[i].x, -float(i & 1));
  EXPECT_NEAR(signed_volume(mirrored.geometry), 1.0, 1e-6);
}

TEST(RenderInputs, SceneAtATimeMovesEachVertexOnAStraightLine) {
  // keyframe 0 at the origin, keyframe 1 translated by (4, 0, 0) and scaled
  // by 3: at time t, corner p sits at (1 - t) p + t (3 p + (4, 0, 0)).
  SceneMesh m = unit_cube(glm::dmat4(1.0));
  m.end_transform = glm::translate(glm::dmat4(1.0), glm::dvec3(4, 0, 0)) * glm::scale(glm::dmat4(1.0), glm::dvec3(3));
  SceneDescription s = one_mesh_scene(m);
  SceneSphere moving = SceneSphere::still({0, 0, 0}, 1.0, 0);
  moving.moving = true;
  moving.end_center = {0, 8, 0};
  moving.end_radius = 3.0;
  s.spheres.push_back(moving);
  for (double t : {0.0, 0.25, 1.0}) {
    FlatScene flat = flatten(scene_at(s, t));
    for (int i = 0; i < 8; ++i) {
      glm::dvec3 p(i & 1, (i >> 1) & 1, (i >> 2) & 1);
      expect_near(glm::dvec3(flat.geometry.vertices[i]), (1 - t) * p + t * (3.0 * p + glm::dvec3(4, 0, 0)), 1e-6,
                  "corner");
    }
    expect_near(glm::dvec3(flat.geometry.spheres[0].center), {0, 8 * t, 0}, 1e-6, "sphere centre");
    EXPECT_NEAR(flat.geometry.spheres[0].radius, 1 + 2 * t, 1e-6);
  }
}

TEST(RenderInputs, EmissiveTrianglesBecomeTriangleLightsByAreaShare) {
  // Two emitting triangles of areas 1/2 and 2 (shares 1/5 and 4/5) and one
  // dark one; the emissive light's colour 0.5 and intensity 3.
  SceneMesh m;
  m.name = "emitters";
  m.edit_shape().vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 5}, {2, 0, 5}, {0, 2, 5}, {9, 9, 9}, {9, 9, 8}, {9, 8, 9}};
  m.edit_shape().triangles = {{0, 1, 2}, {6, 7, 8}, {3, 4, 5}};
  m.edit_shape().materials = {1, 0, 1};
  SceneDescription s = one_mesh_scene(m);
  Material glow;
  glow.emission = {2.0f, 4.0f, 8.0f};
  s.materials.push_back(glow);
  Light emissive;
  emissive.shape = LightShape::emissive;
  emissive.color = glm::vec3(0.5f);
  emissive.intensity = 3.0f;
  Light point;
  point.position = {1, 2, 3};
  s.lights = {point, emissive};
  std::vector<Light> lights = expand_emissive_lights(s, flatten(s));
  ASSERT_EQ(lights.size(), 3u);
  EXPECT_EQ(lights[0].shape, LightShape::point);
  EXPECT_EQ(lights[0].position, glm::vec3(1, 2, 3));
  const double share[2] = {0.2, 0.8};
  const glm::vec3 corner[2] = {{0, 0, 0}, {0, 0, 5}};
  const float edge[2] = {1.0f, 2.0f};
  for (int k = 0; k < 2; ++k) {
    const Light& l = lights[1 + k];
    EXPECT_EQ(l.shape, LightShape::triangle);
    EXPECT_EQ(l.position, corner[k]);
    EXPECT_EQ(l.edge1, glm::vec3(edge[k], 0, 0));
    EXPECT_EQ(l.edge2, glm::vec3(0, edge[k], 0));
    expect_near(glm::dvec3(l.color), glm::dvec3(2, 4, 8) * 0.5 * share[k], 1e-6, "colour");
    EXPECT_EQ(l.intensity, 3.0f);
  }
}

TEST(RenderInputs, ConcentricDiscMapsSquareToDiscInClosedForm) {
  // Shirley and Chiu: the square's centre to the disc's, the middle of each
  // square edge to the disc's boundary on the axes, the square's diagonal
  // point (3/4, 3/4) to radius 1/2 at 45 degrees.
  const struct {
    float u, v;
    double x, y;
  } cases[] = {{0.5f, 0.5f, 0, 0},   {1.0f, 0.5f, 1, 0},  {0.0f, 0.5f, -1, 0},
               {0.5f, 1.0f, 0, 1},   {0.5f, 0.0f, 0, -1}, {0.75f, 0.75f, 0.5 / std::sqrt(2.0), 0.5 / std::sqrt(2.0)},
               {1.0f, 1.0f, std::sqrt(0.5), std::sqrt(0.5)}};
  for (const auto& c : cases) {
    float x, y;
    rtcl_concentric_disc(c.u, c.v, &x, &y);
    EXPECT_NEAR(x, c.x, 1e-6) << c.u << ", " << c.v;
    EXPECT_NEAR(y, c.y, 1e-6) << c.u << ", " << c.v;
  }
  // area-preserving: the central square |2u - 1|, |2v - 1| < 1/2, a quarter
  // of the unit square, maps onto radius < 1/2, a quarter of the disc
  int inside = 0, total = 0;
  for (int i = 0; i < 64; ++i)
    for (int j = 0; j < 64; ++j) {
      float x, y;
      rtcl_concentric_disc((i + 0.5f) / 64.0f, (j + 0.5f) / 64.0f, &x, &y);
      inside += x * x + y * y < 0.25f;
      ++total;
    }
  EXPECT_NEAR(double(inside) / total, 0.25, 0.01);
}

TEST(RenderInputs, StratifiedTimesTakeOneStratumEach) {
  for (std::uint32_t count : {1u, 2u, 5u, 16u})
    for (std::uint32_t pixel : {0u, 7u, 100000u}) {
      std::set<std::uint32_t> strata;
      for (std::uint32_t i = 0; i < count; ++i) {
        float t = rtcl_sample_time(RTCL_SAMPLER_STRATIFIED, 3u, pixel, i, count);
        ASSERT_TRUE(t >= 0.0f && t < 1.0f) << t;
        strata.insert(static_cast<std::uint32_t>(t * count));
      }
      EXPECT_EQ(strata.size(), count) << count << " samples of pixel " << pixel;
    }
}

// Every 2D decision of a path has a dimension of its own: the sub-pixel
// position, the lens, each light at each bounce and the glossy lobe at each
// bounce, numbered 2 + depth (lights + 1) + light (glossy: light = lights).
TEST(RenderInputs, EachDecisionOfAPathHasItsOwnDimension) {
  for (std::uint32_t lights : {0u, 1u, 3u}) {
    std::set<std::uint32_t> seen = {RTCL_DIM_PIXEL, RTCL_DIM_LENS, RTCL_DIM_TIME};
    std::size_t decisions = 3;
    for (std::uint32_t depth = 0; depth < 6; ++depth) {
      for (std::uint32_t l = 0; l < lights; ++l) {
        EXPECT_EQ(rtcl_dimension_light(depth, lights, l), 2 + depth * (lights + 1) + l);
        seen.insert(rtcl_dimension_light(depth, lights, l));
        ++decisions;
      }
      EXPECT_EQ(rtcl_dimension_glossy(depth, lights), 2 + depth * (lights + 1) + lights);
      seen.insert(rtcl_dimension_glossy(depth, lights));
      ++decisions;
    }
    EXPECT_EQ(seen.size(), decisions) << lights << " lights";
  }
}

TEST(RenderInputs, OrthonormalBasisCompletesAnyUnitVector) {
  for (glm::dvec3 n : {glm::dvec3(0, 0, 1), glm::dvec3(0, 0, -1), glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0),
                       glm::normalize(glm::dvec3(1, 2, -3)), glm::normalize(glm::dvec3(-1e-9, 1e-9, -1))}) {
    glm::dvec3 t1, t2;
    orthonormal_basis(n, t1, t2);
    EXPECT_NEAR(glm::length(t1), 1.0, 1e-12);
    EXPECT_NEAR(glm::length(t2), 1.0, 1e-12);
    EXPECT_NEAR(glm::dot(t1, t2), 0.0, 1e-12);
    EXPECT_NEAR(glm::dot(t1, n), 0.0, 1e-12);
    EXPECT_NEAR(glm::dot(t2, n), 0.0, 1e-12);
    expect_near(glm::cross(t1, t2), n, 1e-12, "right-handed: t1 x t2 = n");
  }
}

}  // namespace
}  // namespace rtcl::test
