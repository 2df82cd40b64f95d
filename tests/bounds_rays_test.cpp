// Ray tests of the bounding volumes (kernels/shared/volumes.h) on the host
// and on the device (kernels/bounds/volume_rays.cl): conservative — no ray
// that meets the contents is rejected — against a double-precision brute
// force over the enclosed triangles, for random rays, rays through the
// triangles' vertices and edge midpoints, axis-parallel rays with ±0
// components lying in the volumes' slab planes, grazing rays along edges, and
// rays starting inside; invalid rays miss.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "rtcl/bounds/kdop.hpp"
#include "rtcl/bounds/obb.hpp"
#include "rtcl/bounds/point_input.hpp"
#include "rtcl/bounds/sphere_bounds.hpp"
#include "rtcl/bounds/volume_rays.hpp"
#include "rtcl/opencl.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/fixtures.hpp"
#include "support/reference.hpp"

namespace rtcl::test {
namespace {

constexpr float inf = std::numeric_limits<float>::infinity();

// A ray meets the contents when the double-precision reference meets one of
// the triangles at t in [tmin, tmax] on or inside its edges (margin >= 0).
bool reference_meets(const Geometry& g, const Ray& r) {
  Tolerance tol = tolerance_for(g, r);
  for (std::uint32_t prim = 0; prim < g.triangles.size(); ++prim) {
    PrimHit h = reference_intersect(g, prim, r, tol);
    if (h.plane && h.margin >= 0.0 && h.t >= r.tmin && h.t <= r.tmax) return true;
  }
  return false;
}

// o + t d passes exactly (in exact arithmetic on the floats) through p at
// t = 1 when p - d == o with no rounding; such rays meet the contents at p.
bool exact_aim(const glm::vec3& p, const glm::vec3& o, Ray* ray) {
  glm::vec3 d = p - o;
  for (int k = 0; k < 3; ++k)
    if (static_cast<double>(o[k]) + static_cast<double>(d[k]) != static_cast<double>(p[k])) return false;
  *ray = {o.x, o.y, o.z, d.x, d.y, d.z, 0.0f, inf};
  return true;
}

struct RaySet {
  std::vector<Ray> rays;
  std::vector<char> must_hit;  // the ray certainly meets the contents
};

RaySet adversarial_rays(const Geometry& g, std::uint32_t seed, std::size_t random_count) {
  RaySet s;
  auto add = [&](const Ray& r, bool must) {
    s.rays.push_back(r);
    s.must_hit.push_back(must);
  };
  for (const Ray& r : random_rays(g, random_count, seed)) add(r, reference_meets(g, r));
  std::mt19937 rng(seed);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  Aabb box = g.bounds();
  float radius = glm::length(box.extent());
  std::size_t stride = std::max<std::size_t>(1, g.triangles.size() / 150);
  for (std::size_t t = 0; t < g.triangles.size(); t += stride) {
    const glm::uvec3& tri = g.triangles[t];
    glm::vec3 v[3] = {g.vertices[tri.x], g.vertices[tri.y], g.vertices[tri.z]};
    for (int k = 0; k < 3; ++k) {
      const glm::vec3& p = v[k];
      // From random outside points, through the vertex.
      for (int attempt = 0; attempt < 8; ++attempt) {
        glm::vec3 o = box.center() + radius * glm::normalize(glm::vec3(normal(rng), normal(rng), normal(rng)));
        Ray r;
        if (exact_aim(p, o, &r)) add(r, true);
      }
      // Axis-parallel through the vertex, both directions, both signs of
      // zero: lies in the AABB's planes when the vertex is extreme.
      for (int axis = 0; axis < 3; ++axis)
        for (float sign : {1.0f, -1.0f})
          for (float zero : {0.0f, -0.0f}) {
            float d[3] = {zero, zero, zero};
            d[axis] = sign;
            float o[3] = {p.x, p.y, p.z};
            o[axis] = p[axis] - sign * 2.0f * radius;
            add({o[0], o[1], o[2], d[0], d[1], d[2], 0.0f, inf}, true);
          }
      // Grazing: along the edge to the next vertex, from before it.
      const glm::vec3& q = v[(k + 1) % 3];
      Ray r;
      if (exact_aim(p, p - (q - p), &r)) add(r, true);
      // Starting at the vertex, any direction.
      glm::vec3 dir(normal(rng), normal(rng), normal(rng));
      add({p.x, p.y, p.z, dir.x, dir.y, dir.z, 0.0f, inf}, true);
      // Through the edge midpoint (the float midpoint: within half an ulp of
      // the edge; the reference decides).
      glm::vec3 m = 0.5f * (p + q);
      glm::vec3 o = box.center() + radius * glm::normalize(glm::vec3(normal(rng), normal(rng), normal(rng)));
      Ray rm{o.x, o.y, o.z, m.x - o.x, m.y - o.y, m.z - o.z, 0.0f, inf};
      add(rm, reference_meets(g, rm));
    }
  }
  // Invalid rays: must miss (checked separately).
  return s;
}

std::vector<Ray> invalid_rays(const Geometry& g) {
  glm::vec3 c = g.bounds().center();
  float nan = std::numeric_limits<float>::quiet_NaN();
  return {{c.x, c.y, c.z, 0.0f, 0.0f, 0.0f, 0.0f, inf},    {c.x, c.y, c.z, -0.0f, 0.0f, -0.0f, 0.0f, inf},
          {nan, c.y, c.z, 1.0f, 0.0f, 0.0f, 0.0f, inf},     {c.x, c.y, c.z, 1.0f, inf, 0.0f, 0.0f, inf},
          {c.x, c.y, c.z, 1.0f, 0.0f, 0.0f, nan, inf},      {c.x, c.y, c.z, 1.0f, 0.0f, 0.0f, 2.0f, 1.0f},
          {c.x, c.y, c.z, 1.0f, 0.0f, 0.0f, 0.0f, nan}};
}

struct Volumes {
  std::vector<std::pair<std::string, SlabVolume>> slabs;
  std::vector<std::pair<std::string, SphereVolume>> spheres;
};

Volumes volumes_of(const Geometry& g) {
  std::vector<glm::vec3> pts = used_vertices(g);
  Volumes v;
  v.slabs.emplace_back("obb", obb_of_points(pts, g.source).record());
  for (int count : kdop_direction_counts())
    v.slabs.emplace_back("kdop" + std::to_string(count), kdop_of_points(pts, count, g.source).record());
  v.spheres.emplace_back("ritter", ritter_sphere(pts, g.source).record());
  v.spheres.emplace_back("iterated", iterated_ritter_sphere(pts, g.source).record());
  v.spheres.emplace_back("exact", exact_sphere(pts, g.source).record());
  return v;
}

template <class V>
std::vector<int> run_device(const V& volume, const std::vector<Ray>& rays, const char* kernel_name) {
  const Device& device = test_device();
  cl::Program program = device.program("bounds/volume_rays.cl", {});
  std::vector<int> hit(rays.size(), -1);
  with_cl_errors([&] {
    cl::Buffer vb = device.upload(&volume, sizeof(V), "test volume");
    cl::Buffer rb = device.upload(rays.data(), rays.size() * sizeof(Ray), "test rays");
    cl::Buffer hb = device.allocate(rays.size() * sizeof(int), "test hit flags");
    cl::Buffer tb = device.allocate(rays.size() * sizeof(float), "test entry distances");
    cl::Kernel k(program, kernel_name);
    k.setArg(0, vb);
    k.setArg(1, rb);
    k.setArg(2, static_cast<cl_uint>(rays.size()));
    k.setArg(3, hb);
    k.setArg(4, tb);
    device.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(rays.size()));
    device.queue().enqueueReadBuffer(hb, CL_TRUE, 0, hit.size() * sizeof(int), hit.data());
  });
  return hit;
}

void expect_conservative(const Geometry& g, std::uint32_t seed) {
  RaySet set = adversarial_rays(g, seed, 1500);
  std::vector<Ray> bad = invalid_rays(g);
  std::vector<Ray> all = set.rays;
  all.insert(all.end(), bad.begin(), bad.end());
  std::size_t must = 0;
  for (char m : set.must_hit) must += m;
  ASSERT_GT(must, set.rays.size() / 4) << "too few rays meet the contents to test anything";
  Volumes vols = volumes_of(g);
  auto check = [&](const std::string& name, const std::vector<int>& device, auto host_test) {
    std::size_t rejected_device = 0, rejected_host = 0, invalid_hit = 0;
    std::string example;
    for (std::size_t i = 0; i < all.size(); ++i) {
      float t = 0.0f;
      int host = host_test(all[i], &t);
      if (i >= set.rays.size()) {
        invalid_hit += host + (device[i] != 0);
        continue;
      }
      if (!set.must_hit[i]) continue;
      if (!device[i]) ++rejected_device;
      if (!host && example.empty()) {
        const Ray& r = all[i];
        example = "o=(" + std::to_string(r.ox) + "," + std::to_string(r.oy) + "," + std::to_string(r.oz) + ") d=(" +
                  std::to_string(r.dx) + "," + std::to_string(r.dy) + "," + std::to_string(r.dz) + ")";
      }
      rejected_host += !host;
    }
    EXPECT_EQ(rejected_device, 0u) << g.source << ", " << name << " on the device";
    EXPECT_EQ(rejected_host, 0u) << g.source << ", " << name << " on the host; e.g. " << example;
    EXPECT_EQ(invalid_hit, 0u) << g.source << ", " << name << ": an invalid ray hit";
  };
  for (const auto& [name, v] : vols.slabs)
    check(name, run_device(v, all, "intersect_slab_volume_rays"),
          [&](const Ray& r, float* t) { return intersect_slab_volume(&v, &r, t); });
  for (const auto& [name, v] : vols.spheres)
    check(name, run_device(v, all, "intersect_sphere_volume_rays"),
          [&](const Ray& r, float* t) { return intersect_sphere_volume(&v, &r, t); });
}

TEST(BoundsRays, NeverRejectARayThatMeetsTheContentsRandomSoups) {
  expect_conservative(random_soup(300, 1), 1);
  expect_conservative(random_soup(200, 2, 0.02f, 1e-4f, glm::vec3(-3e-5f)), 2);      // tiny
  expect_conservative(random_soup(200, 3, 0.05f, 10.0f, glm::vec3(1e5f, -2e5f, 3e4f)), 3);  // far
}

TEST(BoundsRays, NeverRejectARayThatMeetsTheContentsSharedMeshes) {
  for (const char* file : {"cornell_box/CornellBox-Original.obj", "teapot/teapot.obj"}) {
    Geometry g = load_mesh(scene_path(file)).geometry;
    expect_conservative(g, 7);
  }
}

TEST(BoundsRays, RaysMissingTheVolumeAreRejectedAndEntryIsOrdered) {
  // Away from the volume by far more than the margin: rejected; a ray from
  // outside towards the centre enters at t > 0 before the centre.
  std::vector<glm::vec3> pts = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  std::vector<SlabVolume> slabs = {obb_of_points(pts, "p").record(), kdop_of_points(pts, 13, "p").record(),
                                   kdop_of_points(pts, 4, "p").record()};
  SphereVolume sphere = exact_sphere(pts, "p").record();
  Ray away{5, 5, 5, 1, 0, 0, 0, inf}, behind{0.5f, 0.5f, 3, 0, 0, 1, 0, inf}, toward{0.5f, 0.5f, 3, 0, 0, -1, 0, inf};
  Ray short_ray{0.5f, 0.5f, 3, 0, 0, -1, 0, 0.5f};
  for (const SlabVolume& v : slabs) {
    float t = 0;
    EXPECT_FALSE(intersect_slab_volume(&v, &away, &t));
    EXPECT_FALSE(intersect_slab_volume(&v, &behind, &t));
    EXPECT_FALSE(intersect_slab_volume(&v, &short_ray, &t));
    ASSERT_TRUE(intersect_slab_volume(&v, &toward, &t));
    EXPECT_GT(t, 0.5f);
    EXPECT_LT(t, 2.5f);
  }
  float t = 0;
  EXPECT_FALSE(intersect_sphere_volume(&sphere, &away, &t));
  EXPECT_FALSE(intersect_sphere_volume(&sphere, &behind, &t));
  ASSERT_TRUE(intersect_sphere_volume(&sphere, &toward, &t));
  EXPECT_GT(t, 0.5f);
  EXPECT_LT(t, 2.5f);
  SlabVolume empty{};
  EXPECT_FALSE(intersect_slab_volume(&empty, &toward, &t));
}

}  // namespace
}  // namespace rtcl::test
