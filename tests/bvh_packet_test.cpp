// The packet traversal (kernels/accel/bvh_packet.cl): 8 consecutive rays
// per work-item, used by "bvh-packet" for every call and by "bvh" and
// "bvh-ploc" for Coherence::coherent calls. Its contract is the single-ray
// kernel's answers: the closest t bit for bit (same slab and edge arithmetic
// per lane), the same occlusion for any hit, whatever the packets hold —
// coherent tiles, Morton-ordered secondary rays, random rays, invalid rays
// beside valid ones, and a ray count that is not a multiple of 8. The
// generic suites (adversarial_test, device_test, render_test) cover it
// through accel_names() and coherent calls.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include "rtcl/accel/bvh.hpp"
#include "rtcl/accel/structure_kernels.hpp"
#include "rtcl/render/ray_order.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/fixtures.hpp"
#include "support/reference.hpp"

namespace rtcl::test {
namespace {


// Pinhole camera rays, row-major, looking at the geometry from +z.
std::vector<Ray> camera_rays(const Geometry& g, std::uint32_t width, std::uint32_t height) {
  Aabb box = g.bounds();
  glm::vec3 centre = box.center(), extent = box.extent();
  glm::vec3 eye = centre + glm::vec3(0.1f * extent.x, 0.2f * extent.y, 1.5f * std::max(extent.x, extent.y));
  std::vector<Ray> rays;
  for (std::uint32_t y = 0; y < height; ++y)
    for (std::uint32_t x = 0; x < width; ++x) {
      glm::vec3 target = centre + glm::vec3((static_cast<float>(x) + 0.5f) / static_cast<float>(width) - 0.5f,
                                            0.5f - (static_cast<float>(y) + 0.5f) / static_cast<float>(height),
                                            0.0f) * std::max(extent.x, extent.y) * 1.2f;
      glm::vec3 d = glm::normalize(target - eye);
      rays.push_back({eye.x, eye.y, eye.z, d.x, d.y, d.z, 0.0f, kInf});
    }
  return rays;
}

// Diffuse-like bounce rays from the closest hits of `primary`.
std::vector<Ray> bounce_rays(const Geometry& g, const std::vector<Ray>& primary, const std::vector<Hit>& hits,
                             std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  float offset = 1e-4f * glm::length(g.bounds().extent());
  std::vector<Ray> rays;
  for (std::size_t i = 0; i < primary.size(); ++i) {
    if (hits[i].prim < 0) continue;
    const Ray& r = primary[i];
    glm::vec3 p = glm::vec3(r.ox, r.oy, r.oz) + hits[i].t * glm::vec3(r.dx, r.dy, r.dz);
    glm::vec3 d = glm::normalize(glm::vec3(normal(rng), normal(rng), normal(rng)));
    if (glm::dot(d, glm::vec3(r.dx, r.dy, r.dz)) > 0.0f) d = -d;
    p += offset * d;
    rays.push_back({p.x, p.y, p.z, d.x, d.y, d.z, 0.0f, kInf});
  }
  return rays;
}

// Closest t bit for bit (and the barycentrics where the primitive is the
// same) and hit/miss for any hit, packet against single ray
// (`packet` traced with `coherence`, `single` incoherent).
void expect_same_as_single_ray(const Accel& single, const Accel& packet, const std::vector<Ray>& rays,
                               const char* what, Coherence coherence = Coherence::incoherent) {
  for (Query q : {Query::closest, Query::any}) {
    auto expected = run_query(single, rays, q);
    auto got = run_query(packet, rays, q, coherence);
    std::size_t differ = 0, first = rays.size();
    for (std::size_t i = 0; i < rays.size(); ++i) {
      bool same = q == Query::closest ? std::memcmp(&expected[i].t, &got[i].t, sizeof(float)) == 0
                                      : (expected[i].prim >= 0) == (got[i].prim >= 0);
      // the same triangle: the same barycentrics, to rounding
      if (q == Query::closest && same && got[i].prim == expected[i].prim && got[i].prim >= 0)
        same = std::fabs(got[i].u - expected[i].u) <= 1e-5f && std::fabs(got[i].v - expected[i].v) <= 1e-5f;
      if (!same && differ++ == 0) first = i;
    }
    EXPECT_EQ(differ, 0u) << what << (q == Query::closest ? " closest" : " any") << ": first at ray " << first
                          << " of " << rays.size();
  }
}

TEST(BvhPacket, IsRegistered) {
  auto names = accel_names();
  EXPECT_NE(std::find(names.begin(), names.end(), "bvh-packet"), names.end());
}

// Which kernel a call gets: packets for coherent calls where the structure
// has a packet kernel (every BVH but "bvh-mixed", whose volume filters the
// packet kernel lacks, and the kd-tree), for every call on "bvh-packet" and
// "kdtree-packet", else one ray. On a device other than a CPU coherent calls
// of the structures that choose take one ray per work-item too.
TEST(BvhPacket, CoherenceSelectsTheKernel) {
  Geometry g = random_soup(200, 81);
  for (const std::string& name : accel_names()) {
    SCOPED_TRACE(name);
    auto accel = make_accel(test_device(), name, g);
    bool always = name == "bvh-packet" || name == "kdtree-packet";
    bool packets = always || (((name.rfind("bvh", 0) == 0 && name != "bvh-mixed") || name.rfind("kdtree", 0) == 0) &&
                              packets_for_coherent_calls(test_device().info()));
    EXPECT_EQ(accel->rays_per_work_item(Coherence::incoherent), always ? 8u : 1u);
    EXPECT_EQ(accel->rays_per_work_item(Coherence::coherent), packets ? 8u : 1u);
  }
}

TEST(BvhPacket, CoherentCallsMatchIncoherentOnesOnBunny) {
  Geometry g = bunny();
  for (const char* name : {"bvh", "bvh-ploc"}) {
    SCOPED_TRACE(name);
    auto accel = make_accel(test_device(), name, g);
    std::vector<Ray> tiled = gather<Ray>(camera_rays(g, 128, 128), tile_order(128, 128));
    expect_same_as_single_ray(*accel, *accel, tiled, "primary, tile order", Coherence::coherent);
    std::vector<Ray> bounces = bounce_rays(g, tiled, run_query(*accel, tiled, Query::closest), 9);
    expect_same_as_single_ray(*accel, *accel, bounces, "bounce, hit order", Coherence::coherent);
  }
}

TEST(BvhPacket, MatchesSingleRayInEveryOrderOnBunny) {
  Geometry g = bunny();
  auto single = make_accel(test_device(), "bvh", g);
  auto packet = make_accel(test_device(), "bvh-packet", g);
  EXPECT_EQ(packet->name(), "bvh-packet");
  EXPECT_EQ(packet->stats().node_count, single->stats().node_count);  // the same tree
  std::vector<Ray> rows = camera_rays(g, 256, 256);
  std::vector<Ray> tiled = gather<Ray>(rows, tile_order(256, 256));
  expect_same_as_single_ray(*single, *packet, rows, "primary, row order");
  expect_same_as_single_ray(*single, *packet, tiled, "primary, tile order");
  std::vector<Ray> bounces = bounce_rays(g, tiled, run_query(*single, tiled, Query::closest), 5);
  ASSERT_GT(bounces.size(), 5000u);
  expect_same_as_single_ray(*single, *packet, bounces, "bounce, hit order");
  expect_same_as_single_ray(*single, *packet, gather<Ray>(bounces, morton_order(bounces, g.bounds())),
                            "bounce, Morton order");
}

TEST(BvhPacket, MatchesReferenceOnIncoherentRaysWithSpheres) {
  Geometry g = random_soup(1500, 61);
  std::mt19937 rng(62);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int i = 0; i < 150; ++i) g.spheres.push_back({{unit(rng), unit(rng), unit(rng)}, 0.005f + 0.03f * unit(rng)});
  auto packet = make_accel(test_device(), "bvh-packet", g);
  std::vector<Ray> rays = random_rays(g, 1499, 63);  // not a multiple of 8
  for (Query q : {Query::closest, Query::any}) {
    std::size_t failures = 0;
    auto report = judge_all(g, rays, run_query(*packet, rays, q), q, &failures);
    EXPECT_EQ(failures, 0u) << (q == Query::closest ? "closest: " : "any: ") << (report.empty() ? "" : report[0]);
  }
  auto single = make_accel(test_device(), "bvh", g);
  expect_same_as_single_ray(*single, *packet, rays, "soup with spheres");
}

// Packets whose rays share one direction octant take the frustum
// traversal (one box test per node for the whole packet): loose frusta
// (origins spread over the scene, each ray tested against a leaf's box),
// tight ones (one origin: no such test), rays aimed exactly at mesh
// vertices (which lie on leaf box faces) from spread origins and from one,
// triangles beside spheres, an invalid ray in an otherwise frustum-shaped
// packet, packets with tmin < 0 (not a frustum), axis-parallel rays;
// at every precision level, answers as the single-ray kernel's and (robust,
// exact) the double-precision reference's.
TEST(BvhPacket, FrustumPacketsMatchSingleRaysAndReference) {
  Geometry g = random_soup(1500, 91);
  std::mt19937 rng(92);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int i = 0; i < 100; ++i) g.spheres.push_back({{unit(rng), unit(rng), unit(rng)}, 0.005f + 0.03f * unit(rng)});
  std::vector<Ray> rays;
  std::vector<char> at_vertex;  // per ray: aimed exactly at a mesh vertex
  for (int p = 0; p < 240; ++p) {
    glm::vec3 sign(unit(rng) < 0.5f ? -1.0f : 1.0f, unit(rng) < 0.5f ? -1.0f : 1.0f, unit(rng) < 0.5f ? -1.0f : 1.0f);
    float spread = p % 3 == 0 ? 1.0f : p % 3 == 1 ? 0.05f : 0.0f;  // origins: whole scene, a patch, one point
    glm::vec3 centre(unit(rng), unit(rng), unit(rng));
    for (int l = 0; l < 8; ++l) {
      glm::vec3 d = sign * glm::vec3(0.05f + unit(rng), 0.05f + unit(rng), 0.05f + unit(rng));
      glm::vec3 o;
      if (p % 4 == 3) {  // aimed at a vertex from 2 units away
        glm::vec3 v = g.vertices[static_cast<std::size_t>(unit(rng) * static_cast<float>(g.vertices.size() - 1))];
        d = glm::normalize(d);
        o = v - 2.0f * d;
      } else {
        o = centre - 1.5f * sign + spread * glm::vec3(unit(rng) - 0.5f, unit(rng) - 0.5f, unit(rng) - 0.5f);
      }
      rays.push_back({o.x, o.y, o.z, d.x, d.y, d.z, 0.0f, kInf});
      at_vertex.push_back(p % 4 == 3);
    }
  }
  for (int p = 0; p < 60; ++p) {  // one origin each (tight frusta): aimed at vertices, or from inside with tmin < 0
    glm::vec3 sign(unit(rng) < 0.5f ? -1.0f : 1.0f, unit(rng) < 0.5f ? -1.0f : 1.0f, unit(rng) < 0.5f ? -1.0f : 1.0f);
    glm::vec3 o = glm::vec3(unit(rng), unit(rng), unit(rng)) - 1.5f * sign;
    bool behind = p % 5 == 4;  // not a frustum: the rays start inside the scene at tmin = -0.5
    if (behind) o += 1.5f * sign;
    for (int l = 0; l < 8; ++l) {
      glm::vec3 v = g.vertices[static_cast<std::size_t>(unit(rng) * static_cast<float>(g.vertices.size() - 1))];
      glm::vec3 d = behind ? sign * glm::vec3(0.05f + unit(rng), 0.05f + unit(rng), 0.05f + unit(rng)) : v - o;
      rays.push_back({o.x, o.y, o.z, d.x, d.y, d.z, behind ? -0.5f : 0.0f, kInf});
      at_vertex.push_back(!behind);
    }
  }
  rays[8 * 5 + 3].dx = kNaN;  // inactive lane in a frustum packet
  for (int l = 0; l < 8; ++l) {  // axis-parallel rays (infinite reciprocals): not a frustum
    float y = 0.1f + 0.1f * static_cast<float>(l);
    rays.push_back({-1.0f, y, 0.5f, 1.0f, 0.0f, 0.0f, 0.0f, kInf});
    at_vertex.push_back(false);
  }
  rays.resize(rays.size() - 3);  // a partial last packet
  for (Precision level : {Precision::fast, Precision::robust, Precision::exact}) {
    SCOPED_TRACE(std::string(precision_name(level)));
    auto packet = make_accel(test_device(), "bvh-packet", g, {level});
    auto single = make_accel(test_device(), "bvh", g, {level});
    if (level == Precision::fast) {
      // not watertight: the same answers as the single-ray kernel, t to
      // rounding, except on rays aimed exactly at a vertex, which either
      // kernel may count as a hit or a miss (Moller-Trumbore under
      // -cl-fast-relaxed-math rounds each kernel's edge tests its own way:
      // a ray differs on some CPUs)
      for (Query q : {Query::closest, Query::any}) {
        auto expected = run_query(*single, rays, q);
        auto got = run_query(*packet, rays, q);
        std::size_t compared = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
          if (at_vertex[i] && (got[i].prim >= 0) != (expected[i].prim >= 0)) continue;
          ++compared;
          ASSERT_EQ(got[i].prim >= 0, expected[i].prim >= 0) << "ray " << i;
          if (q == Query::closest && got[i].prim >= 0)
            EXPECT_NEAR(got[i].t, expected[i].t, 1e-5f * std::abs(expected[i].t)) << "ray " << i;
        }
        EXPECT_GE(compared, rays.size() - rays.size() / 100) << "rays aimed at vertices that the kernels decide apart";
      }
      continue;
    }
    for (Query q : {Query::closest, Query::any}) {
      std::size_t failures = 0;
      auto report = judge_all(g, rays, run_query(*packet, rays, q), q, &failures);
      EXPECT_EQ(failures, 0u) << (q == Query::closest ? "closest: " : "any: ") << (report.empty() ? "" : report[0]);
    }
    expect_same_as_single_ray(*single, *packet, rays, "one-octant packets");
  }
}

// Invalid rays share packets with valid ones; counts 1 .. 17 leave partial
// packets; the hits past ray_count stay untouched.
TEST(BvhPacket, PartialPacketsAndInvalidRaysInAPacket) {
  Geometry g = random_soup(300, 71);
  auto packet = make_accel(test_device(), "bvh-packet", g);
  auto single = make_accel(test_device(), "bvh", g);
  std::vector<Ray> rays = random_rays(g, 24, 72);
  rays[1].dx = kNaN;
  rays[3].dx = rays[3].dy = rays[3].dz = 0.0f;
  rays[4].tmin = 2.0f;
  rays[4].tmax = 1.0f;
  rays[6].oz = kInf;
  expect_same_as_single_ray(*single, *packet, rays, "mixed packet");
  const Device& device = test_device();
  for (std::size_t count = 1; count <= 17; ++count) {
    SCOPED_TRACE("ray_count " + std::to_string(count));
    cl::Buffer ray_buffer = device.upload(rays.data(), rays.size() * sizeof(Ray), "test rays");
    std::vector<Hit> sentinel(rays.size(), Hit{-7.0f, -7.0f, -7.0f, -7});
    cl::Buffer hit_buffer = device.upload(sentinel.data(), sentinel.size() * sizeof(Hit), "test hits");
    std::vector<Hit> hits(rays.size());
    packet->trace(Query::closest, ray_buffer, hit_buffer, count).wait();
    device.queue().enqueueReadBuffer(hit_buffer, CL_TRUE, 0, hits.size() * sizeof(Hit), hits.data());
    std::vector<Ray> prefix(rays.begin(), rays.begin() + static_cast<std::ptrdiff_t>(count));
    auto expected = run_query(*single, prefix, Query::closest);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      if (i < count) {
        EXPECT_EQ(hits[i].prim >= 0, expected[i].prim >= 0) << "ray " << i;
        if (expected[i].prim >= 0) EXPECT_EQ(hits[i].t, expected[i].t) << "ray " << i;
      } else {
        EXPECT_EQ(hits[i].prim, -7) << "hit " << i << " written past ray_count";
      }
    }
    for (int bad : {1, 3, 4, 6})
      if (static_cast<std::size_t>(bad) < count) EXPECT_EQ(hits[bad].prim, -1) << "invalid ray " << bad;
  }
}

}  // namespace
}  // namespace rtcl::test
