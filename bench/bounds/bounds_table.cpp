// The bounding-volume table (docs/structures.md): for every mesh in
// ../shared/scenes and four random point clouds, each volume's size relative
// to the AABB, the three sphere radii, each builder's time, and the
// easy-reject rate: of random rays that hit the AABB but miss the object
// (double-precision brute force over its triangles), the share each volume
// rejects. Prints Markdown. Not a test: run it under the benchmark lock.
//
//   rtcl_bounds_table [RAYS_PER_MESH (default 2000)] [POINTS_PER_CLOUD (default 20000)]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "bench/support/scenes_dir.hpp"
#include "rtcl/bounds/bounds_report.hpp"
#include "rtcl/bounds/point_input.hpp"
#include "rtcl/bounds/volume_rays.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "support/point_clouds.hpp"
#include "support/reference.hpp"

namespace {

using namespace rtcl;

struct Row {
  std::string name;
  BoundsReport report;
  std::vector<double> reject;  // per entry; empty for clouds
  std::size_t candidate_rays = 0;
};

// Rays from a sphere around the AABB (radius: its diagonal) towards uniform
// points inside it: each hits the AABB; kept when the reference (double
// brute force, all threads) finds no triangle. 4 * want candidates, so a
// closed room (sponza, sibenik) yields fewer than `want`.
std::vector<Ray> aabb_only_rays(const Geometry& g, const SlabVolume& aabb, std::size_t want, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  Aabb box = g.bounds();
  float radius = glm::length(box.extent());
  std::vector<Ray> candidates;
  for (std::size_t attempt = 0; attempt < 4 * want; ++attempt) {
    glm::vec3 o = box.center() + radius * glm::normalize(glm::vec3(normal(rng), normal(rng), normal(rng)));
    glm::vec3 target = box.lower + box.extent() * glm::vec3(unit(rng), unit(rng), unit(rng));
    glm::vec3 d = target - o;
    Ray r{o.x, o.y, o.z, d.x, d.y, d.z, 0.0f, INFINITY};
    float t = 0.0f;
    if (intersect_slab_volume(&aabb, &r, &t)) candidates.push_back(r);
  }
  std::vector<Hit> ref = rtcl::test::reference_closest_all(g, candidates);
  std::vector<Ray> out;
  for (std::size_t i = 0; i < candidates.size() && out.size() < want; ++i)
    if (ref[i].prim < 0) out.push_back(candidates[i]);
  return out;
}

Row measure(const std::string& name, const std::vector<glm::vec3>& points, const Geometry* mesh, std::size_t rays) {
  Row row{name, report_bounds(points, name), {}, 0};
  if (!mesh) return row;
  std::vector<Ray> miss = aabb_only_rays(*mesh, row.report.aabb().slabs, rays, 17);
  row.candidate_rays = miss.size();
  for (const BoundEntry& e : row.report.entries) {
    std::size_t rejected = 0;
    for (const Ray& r : miss) {
      float t = 0.0f;
      int hit = e.sphere ? intersect_sphere_volume(&e.ball, &r, &t) : intersect_slab_volume(&e.slabs, &r, &t);
      rejected += !hit;
    }
    row.reject.push_back(miss.empty() ? 0.0 : static_cast<double>(rejected) / miss.size());
  }
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t rays = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 2000;
  std::size_t cloud_points = argc > 2 ? std::strtoul(argv[2], nullptr, 10) : 20000;
  std::filesystem::path dir = rtcl::bench::scenes_dir();
  std::vector<std::filesystem::path> meshes;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
    std::string ext = entry.path().extension().string();
    if (ext == ".obj" || ext == ".ply" || ext == ".stl") meshes.push_back(entry.path());
  }
  std::sort(meshes.begin(), meshes.end());
  std::vector<Row> rows;
  for (const auto& path : meshes) {
    try {
      Geometry g = load_mesh(path.string()).geometry;
      rows.push_back(measure(path.parent_path().filename().string(), used_vertices(g), &g, rays));
      std::fprintf(stderr, "%s done\n", path.string().c_str());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "skipped %s: %s\n", path.string().c_str(), e.what());
    }
  }
  for (const auto& c : rtcl::test::random_clouds(cloud_points, 42))
    rows.push_back(measure(c.name, c.points, nullptr, 0));

  const std::vector<BoundEntry>& first = rows.front().report.entries;
  // The rest of a table's header: one column per volume, after `lead` columns.
  auto volume_columns = [&](int lead) {
    for (const BoundEntry& e : first) std::printf(" %s |", e.name.c_str());
    std::printf("\n|");
    for (int i = 0; i < lead; ++i) std::printf("---|");
    for (std::size_t i = 0; i < first.size(); ++i) std::printf("---|");
    std::printf("\n");
  };
  std::printf("### Volume relative to the AABB\n\n| points |");
  volume_columns(1);
  for (const Row& r : rows) {
    std::printf("| %s (%zu) |", r.name.c_str(), r.report.point_count);
    for (const BoundEntry& e : r.report.entries)
      std::printf(" %.3f |", r.report.aabb().volume > 0 ? e.volume / r.report.aabb().volume : 0.0);
    std::printf("\n");
  }
  std::printf("\n### Surface area relative to the AABB\n\n| points |");
  volume_columns(1);
  for (const Row& r : rows) {
    std::printf("| %s |", r.name.c_str());
    for (const BoundEntry& e : r.report.entries) std::printf(" %.3f |", e.area / r.report.aabb().area);
    std::printf("\n");
  }
  std::printf("\n### Sphere radii (exact = Welzl)\n\n| points | Ritter | iterated | exact | Ritter / exact | iterated / exact |\n|---|---|---|---|---|---|\n");
  for (const Row& r : rows) {
    double e = r.report.exact.radius;
    std::printf("| %s | %.6g | %.6g | %.6g | %.4f | %.4f |\n", r.name.c_str(), r.report.ritter.radius,
                r.report.iterated.radius, e, r.report.ritter.radius / e, r.report.iterated.radius / e);
  }
  // The Ritter / exact ratio over many seeds of each cloud shape (one seed
  // above): the spread, not one draw.
  constexpr int seeds = 25;
  std::printf("\n### Ritter / exact radius over %d seeds per cloud (%zu points)\n\n"
              "| cloud | min | median | max | iterated / exact, max |\n|---|---|---|---|---|\n",
              seeds, cloud_points);
  for (std::size_t shape = 0; shape < 4; ++shape) {
    std::vector<double> ratio, iterated;
    std::string name;
    for (int seed = 0; seed < seeds; ++seed) {
      rtcl::test::PointCloud c = rtcl::test::random_clouds(cloud_points, 1000u + 7u * seed)[shape];
      name = c.name;
      double exact = exact_sphere(c.points, c.name).radius;
      ratio.push_back(ritter_sphere(c.points, c.name).radius / exact);
      iterated.push_back(iterated_ritter_sphere(c.points, c.name).radius / exact);
    }
    std::sort(ratio.begin(), ratio.end());
    std::printf("| %s | %.4f | %.4f | %.4f | %.4f |\n", name.c_str(), ratio.front(), ratio[ratio.size() / 2],
                ratio.back(), *std::max_element(iterated.begin(), iterated.end()));
  }
  std::printf("\n### Build time, ms (host, one thread)\n\n| points |");
  volume_columns(1);
  for (const Row& r : rows) {
    std::printf("| %s |", r.name.c_str());
    for (const BoundEntry& e : r.report.entries) std::printf(" %.3f |", e.build_ms);
    std::printf("\n");
  }
  std::printf("\n### Easy-reject rate: rays that hit the AABB but miss the mesh, share rejected\n\n| mesh | rays |");
  volume_columns(2);
  for (const Row& r : rows) {
    if (r.reject.empty()) continue;
    std::printf("| %s | %zu |", r.name.c_str(), r.candidate_rays);
    for (double x : r.reject) {
      if (r.candidate_rays == 0)
        std::printf(" n/a |");
      else
        std::printf(" %.3f |", x);
    }
    std::printf("\n");
  }
  return 0;
}
