// Motion blur: moving meshes and spheres (two keyframes, rtcl/scene/
// motion.hpp), the motion BVH (swept and interpolated node bounds) against a
// double-precision brute force at fixed times, the renderer against the host
// reference drawing the same times, zero motion against the static scene,
// specialisation (no time code without motion), and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "rtcl/accel/bvh_motion.hpp"
#include "rtcl/error.hpp"
#include "rtcl/render/renderer.hpp"
#include "rtcl/scene/default_scene.hpp"
#include "rtcl/scene/motion.hpp"
#include "rtcl/scene/scene_bytes.hpp"
#include "rtcl/scene/scene_file.hpp"
#include "support/error_of.hpp"
#include "support/fixtures.hpp"
#include "support/reference_renderer.hpp"

namespace rtcl::test {
namespace {

using glm::dvec3;

// ---------------------------------------------------------------- scene files

std::string motion_scene_text(const std::string& object_motion, const std::string& camera_extra = "") {
  return R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0])" + camera_extra +
         R"(}, "materials": {"m": {}},
             "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m")" +
         object_motion + "}]}";
}

TEST(MotionScene, MotionKeyIsTheEndKeyframeAndShutterIsRead) {
  SceneDescription s = parse_scene(motion_scene_text(R"(, "transform": {"translate": [1, 0, 0]}, "motion": {"translate": [0, 2, 0], "scale": 2})",
                                   R"(, "shutter": [0.25, 0.75])"),
                        "m.json", ".");
  ASSERT_EQ(s.spheres.size(), 1u);
  const SceneSphere& sp = s.spheres[0];
  EXPECT_TRUE(sp.moving);
  EXPECT_EQ(sp.center, dvec3(1, 0, 0));
  // motion applies after the transform: translate(0, 2, 0) * scale 2 of the centre (1, 0, 0)
  EXPECT_EQ(sp.end_center, dvec3(2, 2, 0));
  EXPECT_EQ(sp.end_radius, 2.0);
  EXPECT_EQ(s.camera.shutter_open, 0.25f);
  EXPECT_EQ(s.camera.shutter_close, 0.75f);
  EXPECT_TRUE(scene_moves(s));
  SceneSphere mid = sphere_at(sp, 0.5);
  EXPECT_EQ(mid.center, dvec3(1.5, 1, 0));
  EXPECT_EQ(mid.radius, 1.5);
  EXPECT_FALSE(scene_moves(parse_scene(motion_scene_text(""), "m.json", ".")));
}

TEST(MotionScene, BadMotionIsOneErrorNamingTheKey) {
  EXPECT_NE(error_of([] { parse_scene(motion_scene_text(R"(, "motion": {"scale": 0})"), "m.json", "."); })
                .find("objects[0].motion.scale"),
            std::string::npos);
  EXPECT_NE(error_of([] { parse_scene(motion_scene_text(R"(, "motion": {"scale": [1, 2, 1]})"), "m.json", "."); })
                .find("objects[0].motion"),
            std::string::npos);
  EXPECT_NE(error_of([] { parse_scene(motion_scene_text("", R"(, "shutter": [1, 0])"), "m.json", "."); }).find("camera.shutter"),
            std::string::npos);
  EXPECT_NE(error_of([] { parse_scene(motion_scene_text("", R"(, "shutter": [0])"), "m.json", "."); }).find("camera.shutter"),
            std::string::npos);
}

// A mesh whose blended transform becomes singular (a half turn flattens it
// at mid-shutter) is refused naming its motion key; a quarter turn is not.
TEST(MotionScene, SingularBlendIsAnErrorNamingTheMotionKey) {
  SceneDescription s = default_scene();
  SceneMesh& block = s.meshes.at(1);
  block.motion_key = "scene.json: objects[1].motion";
  block.end_transform = glm::rotate(glm::dmat4(1.0), glm::radians(180.0), dvec3(0, 1, 0)) * block.transform;
  std::string e = error_of([&] { check_motion(s, 0.0, 1.0); });
  EXPECT_NE(e.find("objects[1].motion"), std::string::npos) << e;
  EXPECT_NE(e.find("singular"), std::string::npos) << e;
  block.end_transform = glm::rotate(glm::dmat4(1.0), glm::radians(90.0), dvec3(0, 1, 0)) * block.transform;
  EXPECT_NO_THROW(check_motion(s, 0.0, 1.0));
  // A scale motion through zero, outside [0, 1]: 1 -> 0.5 reaches 0 at time 2.
  block.end_transform = block.transform * glm::scale(glm::dmat4(1.0), dvec3(0.5));
  EXPECT_NO_THROW(check_motion(s, 0.0, 1.0));
  EXPECT_NE(error_of([&] { check_motion(s, 1.5, 2.5); }).find("objects[1].motion"), std::string::npos);
}

// The broadcast form (rtcl render under mpirun) keeps both keyframes, the
// shutter and the motion keys.
TEST(MotionScene, SceneBytesKeepTheKeyframes) {
  SceneDescription s = parse_scene(motion_scene_text(R"(, "motion": {"translate": [0, 2, 0]})", R"(, "shutter": [0.1, 0.6])"), "m.json", ".");
  s.meshes.push_back(default_scene().meshes.at(1));
  s.meshes.back().end_transform = glm::translate(glm::dmat4(1.0), dvec3(1, 0, 0)) * s.meshes.back().transform;
  s.meshes.back().motion_key = "m.json: objects[1].motion";
  s.materials.push_back(default_scene().materials.at(5));
  s.meshes.back().edit_shape().materials.assign(s.meshes.back().triangles().size(), 1);
  SceneDescription r = scene_from_bytes(scene_to_bytes(s), "bytes");
  EXPECT_EQ(r.camera.shutter_open, 0.1f);
  EXPECT_EQ(r.camera.shutter_close, 0.6f);
  ASSERT_TRUE(r.spheres.at(0).moving);
  EXPECT_EQ(r.spheres[0].end_center, s.spheres[0].end_center);
  EXPECT_EQ(r.spheres[0].motion_key, s.spheres[0].motion_key);
  ASSERT_TRUE(r.meshes.at(0).end_transform.has_value());
  EXPECT_EQ(*r.meshes[0].end_transform, *s.meshes[0].end_transform);
  EXPECT_EQ(r.meshes[0].motion_key, "m.json: objects[1].motion");
}

// ------------------------------------------------- the motion BVH, brute force

struct MovingSoup {
  Geometry open, close;
};

// Triangles and spheres in [0, 1]^3 * scale, each moving by its own
// translation (up to 0.3 * scale) and a slight rotation about its centre:
// overlapping swept boxes, every triangle's shape changing.
MovingSoup moving_soup(std::uint32_t seed, float scale) {
  MovingSoup m;
  m.open = random_soup(400, seed, 0.08f, scale);
  m.close = m.open;
  std::mt19937 rng(seed + 7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (std::size_t t = 0; t < m.open.triangles.size(); ++t) {
    glm::vec3 shift = 0.3f * scale * glm::vec3(u(rng), u(rng), u(rng));
    glm::vec3 c = (m.open.vertices[m.open.triangles[t][0]] + m.open.vertices[m.open.triangles[t][1]] +
                   m.open.vertices[m.open.triangles[t][2]]) / 3.0f;
    glm::dmat4 r = glm::rotate(glm::dmat4(1.0), double(u(rng)), glm::normalize(dvec3(u(rng), u(rng), u(rng)) + 1e-3));
    for (int k = 0; k < 3; ++k) {
      std::uint32_t v = m.open.triangles[t][k];
      m.close.vertices[v] = c + shift + glm::vec3(glm::dmat3(r) * dvec3(m.open.vertices[v] - c));
    }
  }
  for (int i = 0; i < 6; ++i) {
    Sphere s{scale * glm::vec3(0.5f + 0.4f * u(rng), 0.5f + 0.4f * u(rng), 0.5f + 0.4f * u(rng)), scale * 0.05f};
    m.open.spheres.push_back(s);
    s.center += 0.3f * scale * glm::vec3(u(rng), u(rng), u(rng));
    s.radius *= 1.5f;
    m.close.spheres.push_back(s);
  }
  return m;
}

struct RefHit {
  double t = std::numeric_limits<double>::infinity();
  int prim = -1;
  double margin = 1.0;  // how far inside its triangle (relative barycentric) or sphere the hit lies
};

// Double-precision brute force over the keyframes interpolated at tau (in
// double, from the float keyframes); `slack` > 0 also accepts hits that
// miss a primitive by that relative margin (grazing rays).
RefHit brute_force(const MovingSoup& m, const Ray& r, double tau, double slack = 0.0) {
  dvec3 o(r.ox, r.oy, r.oz), d(r.dx, r.dy, r.dz);
  RefHit best;
  best.t = r.tmax;
  auto at = [&](const glm::vec3& a, const glm::vec3& b) { return dvec3(a) + tau * (dvec3(b) - dvec3(a)); };
  for (std::size_t i = 0; i < m.open.triangles.size(); ++i) {
    dvec3 v[3];
    for (int k = 0; k < 3; ++k) v[k] = at(m.open.vertices[m.open.triangles[i][k]], m.close.vertices[m.close.triangles[i][k]]);
    dvec3 e1 = v[1] - v[0], e2 = v[2] - v[0], p = glm::cross(d, e2);
    double det = glm::dot(e1, p);
    if (det == 0.0) continue;
    dvec3 s = o - v[0];
    double b1 = glm::dot(s, p) / det;
    dvec3 q = glm::cross(s, e1);
    double b2 = glm::dot(d, q) / det;
    double t = glm::dot(e2, q) / det;
    if (b1 < -slack || b2 < -slack || b1 + b2 > 1 + slack || t < r.tmin || t > best.t) continue;
    best = {t, int(i), std::min({b1, b2, 1.0 - b1 - b2})};
  }
  for (std::size_t i = 0; i < m.open.spheres.size(); ++i) {
    dvec3 c = at(m.open.spheres[i].center, m.close.spheres[i].center);
    double rad = double(m.open.spheres[i].radius) + tau * (double(m.close.spheres[i].radius) - m.open.spheres[i].radius);
    dvec3 f = o - c;
    double a = glm::dot(d, d), b = glm::dot(f, d), disc = b * b - a * (glm::dot(f, f) - rad * rad);
    if (disc < -slack * a * rad * rad) continue;
    double sq = std::sqrt(std::max(disc, 0.0));
    for (double t : {(-b - sq) / a, (-b + sq) / a})
      if (t >= r.tmin && t <= best.t) {
        best = {t, int(m.open.triangles.size() + i), disc / (a * rad * rad)};
        break;
      }
  }
  if (best.prim < 0) best.t = std::numeric_limits<double>::infinity();
  return best;
}

// Random rays at the soup, plus adversarial ones: axis-parallel with +-0
// components, and rays aimed exactly at keyframe vertices (shared vertices
// of the soup at time 0 and 1).
std::vector<Ray> motion_rays(const MovingSoup& m, std::uint32_t seed) {
  std::vector<Ray> rays = random_rays(m.open, 1500, seed);
  Aabb box = merge(m.open.bounds(), m.close.bounds());
  glm::vec3 c = box.center(), e = box.extent();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int axis = 0; axis < 3; ++axis)
    for (float sign : {1.0f, -1.0f})
      for (int k = 0; k < 40; ++k) {
        glm::vec3 o = box.lower + e * glm::vec3(u(rng), u(rng), u(rng));
        o[axis] = sign > 0 ? box.lower[axis] - e[axis] : box.upper[axis] + e[axis];
        glm::vec3 d(k % 2 ? 0.0f : -0.0f);
        d[axis] = sign;
        rays.push_back(Ray{o.x, o.y, o.z, d.x, d.y, d.z, 0.0f, INFINITY});
      }
  for (std::size_t v = 0; v < 60; ++v) {
    glm::vec3 target = (v % 2 ? m.close : m.open).vertices[v * 7 % m.open.vertices.size()];
    glm::vec3 o = c + 2.0f * e;
    glm::vec3 d = target - o;
    rays.push_back(Ray{o.x, o.y, o.z, d.x, d.y, d.z, 0.0f, INFINITY});
  }
  return rays;
}

std::vector<Hit> run_motion(const MotionBvh& bvh, const std::vector<Ray>& rays, const std::vector<float>& times,
                            Query query) {
  const Device& dev = test_device();
  cl::Buffer ray_buf = dev.upload(rays.data(), rays.size() * sizeof(Ray), "rays");
  cl::Buffer time_buf = dev.upload(times.data(), times.size() * sizeof(float), "times");
  cl::Buffer hit_buf = dev.allocate(rays.size() * sizeof(Hit), "hits");
  cl::Event e = bvh.trace(query, ray_buf, RayTimes{time_buf}, hit_buf, rays.size());
  std::vector<Hit> hits(rays.size());
  std::vector<cl::Event> wait{e};
  dev.queue().enqueueReadBuffer(hit_buf, CL_TRUE, 0, hits.size() * sizeof(Hit), hits.data(), &wait);
  return hits;
}

// Closest and any hit at fixed times, both node-bound forms, two scales:
// every hit the brute force finds clearly inside a primitive (relative
// margin above 1e-4) is found, at the same primitive and t within 1e-5 of
// the scene's size; no hit where the brute force finds clearly none.
TEST(MotionBvh, AgreesWithDoubleBruteForceAtFixedTimes) {
  for (float scale : {1.0f, 1e4f}) {
    MovingSoup m = moving_soup(11, scale);
    std::vector<Ray> rays = motion_rays(m, 5);
    double size = glm::length(glm::dvec3(merge(m.open.bounds(), m.close.bounds()).extent()));
    for (MotionBounds bounds : {MotionBounds::swept, MotionBounds::interpolated}) {
      MotionBvh bvh(test_device(), m.open, m.close, bounds);
      for (float tau : {0.0f, 0.25f, 0.5f, 1.0f, -1.0f}) {
        std::vector<float> times(rays.size());
        std::mt19937 rng(3);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        for (float& t : times) t = tau >= 0.0f ? tau : u(rng);  // -1: every ray its own random time
        std::vector<Hit> closest = run_motion(bvh, rays, times, Query::closest);
        std::vector<Hit> any = run_motion(bvh, rays, times, Query::any);
        std::size_t checked = 0, hits = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
          RefHit ref = brute_force(m, rays[i], times[i]);
          if (ref.prim >= 0 && ref.margin < 1e-4) continue;  // grazing an edge or a sphere's rim
          RefHit loose = brute_force(m, rays[i], times[i], 1e-4);
          if (ref.prim >= 0 && loose.prim != ref.prim) continue;  // a nearer primitive grazed (a corner the ray aims at)
          ++checked;
          double dir = glm::length(dvec3(rays[i].dx, rays[i].dy, rays[i].dz));
          std::string what = std::string(motion_bounds_name(bounds)) + " scale " + std::to_string(scale) +
                             " time " + std::to_string(times[i]) + " ray " + std::to_string(i);
          if (ref.prim < 0) {
            // The device may hit only where the ray passes within rounding
            // of an edge or rim.
            if (closest[i].prim >= 0) EXPECT_GE(brute_force(m, rays[i], times[i], 1e-4).prim, 0) << what;
            continue;
          }
          ++hits;
          EXPECT_EQ(closest[i].prim, ref.prim) << what;
          EXPECT_NEAR(closest[i].t * dir, ref.t * dir, 1e-5 * size) << what;
          EXPECT_GE(any[i].prim, 0) << what;
        }
        EXPECT_GT(hits, rays.size() / 10);
        EXPECT_GT(checked, rays.size() * 9 / 10);
      }
    }
  }
}

// A ray passing where a primitive is at time 0 but not at time 1 (and the
// reverse): hit and miss follow the ray's time, at both ends of the shutter.
TEST(MotionBvh, HitsFollowTheRayTime) {
  Geometry open, close;
  open.vertices = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
  open.triangles = {{0, 1, 2}};
  close = open;
  for (glm::vec3& v : close.vertices) v.x += 10.0f;  // moved 10 to the right
  std::vector<Ray> rays = {Ray{0, 0, 5, 0, 0, -1, 0, INFINITY}, Ray{10, 0, 5, 0, 0, -1, 0, INFINITY},
                           Ray{5, 0, 5, -0.0f, 0.0f, -1, 0, INFINITY}};
  for (MotionBounds bounds : {MotionBounds::swept, MotionBounds::interpolated}) {
    MotionBvh bvh(test_device(), open, close, bounds);
    std::vector<Hit> at0 = run_motion(bvh, rays, {0.0f, 0.0f, 0.0f}, Query::closest);
    std::vector<Hit> at1 = run_motion(bvh, rays, {1.0f, 1.0f, 1.0f}, Query::closest);
    std::vector<Hit> mid = run_motion(bvh, rays, {0.5f, 0.5f, 0.5f}, Query::closest);
    EXPECT_EQ(at0[0].prim, 0);
    EXPECT_EQ(at0[1].prim, -1);
    EXPECT_EQ(at1[0].prim, -1);
    EXPECT_EQ(at1[1].prim, 0);
    EXPECT_EQ(mid[2].prim, 0);
    EXPECT_EQ(mid[0].prim, -1);
    EXPECT_FLOAT_EQ(at0[0].t, 5.0f);
  }
}

// Times beyond the shutter are clamped to it and a NaN time is time 0, at
// every level (the fast level's fast math, which may assume no NaN,
// included).
TEST(MotionBvh, TimesAreClampedAndNaNIsTimeZero) {
  Geometry open, close;
  open.vertices = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
  open.triangles = {{0, 1, 2}};
  close = open;
  for (glm::vec3& v : close.vertices) v.x += 10.0f;
  const std::vector<Ray> rays = {Ray{0, 0, 5, 0, 0, -1, 0, INFINITY}, Ray{10, 0, 5, 0, 0, -1, 0, INFINITY}};
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (Precision level : test_precisions()) {
    AccelConfig config;
    config.precision = level;
    MotionBvh bvh(test_device(), open, close, MotionBounds::swept, config);
    for (float time : {nan, -5.0f, -INFINITY}) {
      std::vector<Hit> hits = run_motion(bvh, rays, {time, time}, Query::closest);
      EXPECT_TRUE(hits[0].prim == 0 && hits[1].prim == -1) << precision_name(level) << " time " << time;
    }
    for (float time : {5.0f, INFINITY}) {
      std::vector<Hit> hits = run_motion(bvh, rays, {time, time}, Query::closest);
      EXPECT_TRUE(hits[0].prim == -1 && hits[1].prim == 0) << precision_name(level) << " time " << time;
    }
  }
}

TEST(MotionBvh, TraceWithoutTimesIsAnError) {
  MovingSoup m = moving_soup(1, 1.0f);
  MotionBvh bvh(test_device(), m.open, m.close, MotionBounds::swept);
  EXPECT_NE(error_of([&] { run_query(bvh, random_rays(m.open, 8, 1), Query::closest); }).find("times"),
            std::string::npos);
  Geometry other = m.close;
  other.spheres.pop_back();
  EXPECT_NE(error_of([&] { MotionBvh(test_device(), m.open, other, MotionBounds::swept); }).find("same"),
            std::string::npos);
}

// ------------------------------------------------------------- the renderer

// The default scene with the mirror sphere moving right and up, and the
// glass block sliding and turning (a quarter turn).
SceneDescription moving_default_scene() {
  SceneDescription s = default_scene();
  SceneSphere& mirror = s.spheres.at(0);
  mirror.moving = true;
  mirror.end_center = mirror.center + dvec3(0.35, 0.2, 0.0);
  mirror.end_radius = mirror.radius * 0.8;
  SceneMesh& block = s.meshes.at(1);
  block.end_transform = glm::translate(glm::dmat4(1.0), dvec3(-0.3, 0.0, 0.2)) * block.transform *
                        glm::rotate(glm::dmat4(1.0), glm::radians(40.0), dvec3(0, 1, 0));
  return s;
}

RenderSettings small(std::uint32_t size, std::uint32_t spp, Sampler sampler) {
  RenderSettings s;
  s.width = s.height = size;
  s.spp = spp;
  s.sampler = sampler;
  s.seed = 99;
  return s;
}

// Thresholds of distributed_test.cpp: pixels with a stable ray tree differ
// by float rounding (1e-3); at most 2% by more than 0.05.
TEST(MotionRender, MatchesTheReferenceWithTheSameTimes) {
  SceneDescription scene = moving_default_scene();
  scene.camera.shutter_open = 0.2f;
  scene.camera.shutter_close = 0.9f;
  for (MotionBounds bounds : {MotionBounds::swept, MotionBounds::interpolated})
    for (Sampler sampler : {Sampler::stratified, Sampler::sobol}) {
      RenderSettings s = small(24, 4, sampler);
      ReferenceImage ref = reference_render(scene, s);
      Renderer renderer(test_device(), scene, "bvh", {}, bounds);
      EXPECT_TRUE(has(renderer.defines(), "RTCL_HAS_MOTION"));
      EXPECT_EQ(renderer.accel().name(), "bvh-motion");
      ImageDifference d = compare_images(renderer.render(s), ref.image, ref.ambiguous);
      double pixels = double(s.width) * s.height;
      std::printf("[ measure  ] motion %s %s: rmse %.5f, max unambiguous %.2e, over 0.05: %zu of %.0f\n",
                  motion_bounds_name(bounds), sampler_name(sampler).data(), d.rmse, d.max_error_unmasked,
                  d.pixels_over, pixels);
      EXPECT_LE(d.max_error_unmasked, 1e-3);
      EXPECT_LE(d.pixels_over, 0.02 * pixels);
    }
}

// Motion blurs: the moving image differs from both keyframes' static images
// where the objects move, and lies between them on average.
TEST(MotionRender, BlurDiffersFromEitherKeyframe) {
  SceneDescription scene = moving_default_scene();
  RenderSettings s = small(32, 8, Sampler::stratified);
  Image blurred = Renderer(test_device(), scene, "bvh").render(s);
  Image at_open = Renderer(test_device(), scene_at(scene, 0.0), "bvh").render(s);
  Image at_close = Renderer(test_device(), scene_at(scene, 1.0), "bvh").render(s);
  EXPECT_GT(compare_images(blurred, at_open).rmse, 0.01);
  EXPECT_GT(compare_images(blurred, at_close).rmse, 0.01);
}

// Zero motion (end keyframes equal to the start) takes the moving path
// (motion BVH, time code) and gives the static scene's image.
TEST(MotionRender, ZeroMotionEqualsTheStaticScene) {
  SceneDescription still = default_scene();
  SceneDescription zero = still;
  zero.meshes.at(1).end_transform = zero.meshes.at(1).transform;
  zero.spheres.at(0).moving = true;
  zero.spheres.at(0).end_center = zero.spheres.at(0).center;
  zero.spheres.at(0).end_radius = zero.spheres.at(0).radius;
  RenderSettings s = small(32, 2, Sampler::random);
  Renderer moving(test_device(), zero, "bvh");
  Renderer fixed(test_device(), still, "bvh");
  EXPECT_TRUE(has(moving.defines(), "RTCL_HAS_MOTION"));
  EXPECT_FALSE(has(fixed.defines(), "RTCL_HAS_MOTION"));
  ImageDifference d = compare_images(moving.render(s), fixed.render(s));
  std::printf("[ measure  ] zero motion against static: max %.3e\n", d.max_error);
  EXPECT_EQ(d.max_error, 0.0);
}

TEST(MotionRender, MovingSceneNeedsTheBvhAndStaticLamps) {
  SceneDescription scene = moving_default_scene();
  EXPECT_NE(error_of([&] { Renderer(test_device(), scene, "grid"); }).find("Renderer accel \"grid\": "), std::string::npos);
  SceneDescription lamp = scene;
  lamp.lights = {Light{}};
  lamp.lights[0].shape = LightShape::emissive;
  lamp.meshes.at(0).end_transform = glm::translate(glm::dmat4(1.0), dvec3(0, 0.1, 0));
  EXPECT_NE(error_of([&] { Renderer(test_device(), lamp, "bvh"); }).find("emissive"), std::string::npos);
}

}  // namespace
}  // namespace rtcl::test
