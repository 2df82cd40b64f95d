// `rtcl bounds MESH [--json]`: every bounding volume of a mesh's vertices
// (rtcl/bounds/bounds_report.hpp): the AABB, the OBB with its axes, each
// k-DOP with its slabs, the Ritter, iterated and exact spheres with centre
// and radius; volume and surface area relative to the AABB; build time.
// Needs no OpenCL device.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "rtcl/bounds/bounds_report.hpp"
#include "rtcl/bounds/point_input.hpp"
#include "rtcl/scene/mesh_io.hpp"

namespace rtcl::cli {

namespace {

struct BoundsOptions {
  std::string mesh;
  bool json = false;
};

double ratio(double x, double aabb) { return aabb > 0.0 ? x / aabb : (x > 0.0 ? INFINITY : 1.0); }

nlohmann::json vec(glm::vec3 v) { return {v.x, v.y, v.z}; }

nlohmann::json to_json(const BoundsReport& r, const std::string& path) {
  nlohmann::json out;
  out["mesh"] = path;
  out["points"] = r.point_count;
  const BoundEntry& aabb = r.aabb();
  for (const BoundEntry& e : r.entries) {
    nlohmann::json j;
    j["volume"] = e.volume;
    j["area"] = e.area;
    j["volume_vs_aabb"] = ratio(e.volume, aabb.volume);
    j["area_vs_aabb"] = ratio(e.area, aabb.area);
    j["build_ms"] = e.build_ms;
    if (e.sphere) {
      j["center"] = {e.ball.cx, e.ball.cy, e.ball.cz};
      j["radius"] = e.ball.r;
    } else {
      nlohmann::json slabs = nlohmann::json::array();
      for (int i = 0; i < e.slabs.count; ++i)
        slabs.push_back({{"normal", {e.slabs.normal[i][0], e.slabs.normal[i][1], e.slabs.normal[i][2]}},
                         {"d_near", e.slabs.d_near[i]},
                         {"d_far", e.slabs.d_far[i]}});
      j["slabs"] = slabs;
    }
    if (e.name == "obb") {
      j["center"] = vec(r.obb.center());
      j["axes"] = {vec(r.obb.axis[0]), vec(r.obb.axis[1]), vec(r.obb.axis[2])};
      j["half_extent"] = vec(r.obb.half_extent());
    }
    out["volumes"][e.name] = j;
  }
  out["exact_vs_ritter_radius"] = r.ritter.radius > 0 ? r.exact.radius / r.ritter.radius : 1.0;
  return out;
}

void print_text(const BoundsReport& r, const std::string& path) {
  const BoundEntry& aabb = r.aabb();
  std::printf("%s: %zu vertices\n\n", path.c_str(), r.point_count);
  std::printf("%-9s %14s %14s %10s %10s %10s\n", "bound", "volume", "area", "vol/AABB", "area/AABB", "build ms");
  for (const BoundEntry& e : r.entries)
    std::printf("%-9s %14.6g %14.6g %10.4f %10.4f %10.3f\n", e.name.c_str(), e.volume, e.area,
                ratio(e.volume, aabb.volume), ratio(e.area, aabb.area), e.build_ms);
  std::printf("\naabb      lower (%g, %g, %g) upper (%g, %g, %g)\n", aabb.slabs.d_near[0], aabb.slabs.d_near[1],
              aabb.slabs.d_near[2], aabb.slabs.d_far[0], aabb.slabs.d_far[1], aabb.slabs.d_far[2]);
  glm::vec3 c = r.obb.center(), h = r.obb.half_extent();
  std::printf("obb       centre (%g, %g, %g) half extents (%g, %g, %g)\n", c.x, c.y, c.z, h.x, h.y, h.z);
  for (int k = 0; k < 3; ++k)
    std::printf("          axis %d (%.7f, %.7f, %.7f)\n", k, r.obb.axis[k].x, r.obb.axis[k].y, r.obb.axis[k].z);
  for (const BoundEntry& e : r.entries) {
    if (e.sphere) {
      std::printf("%-9s centre (%g, %g, %g) radius %.7g\n", e.name.c_str(), e.ball.cx, e.ball.cy, e.ball.cz, e.ball.r);
    } else if (e.name.rfind("kdop", 0) == 0) {
      std::printf("%-9s %d slabs d_near <= n.x <= d_far:\n", e.name.c_str(), e.slabs.count);
      for (int i = 0; i < e.slabs.count; ++i)
        std::printf("          n (%+.6f, %+.6f, %+.6f)  [%g, %g]\n", e.slabs.normal[i][0], e.slabs.normal[i][1],
                    e.slabs.normal[i][2], e.slabs.d_near[i], e.slabs.d_far[i]);
    }
  }
  std::printf("\nexact / Ritter radius: %.4f   exact / iterated: %.4f\n",
              r.ritter.radius > 0 ? r.exact.radius / r.ritter.radius : 1.0,
              r.iterated.radius > 0 ? r.exact.radius / r.iterated.radius : 1.0);
}

void run_bounds(const BoundsOptions& o) {
  LoadedMesh mesh = load_mesh(o.mesh);
  for (const std::string& note : mesh.notes) std::fprintf(stderr, "rtcl: note: %s\n", note.c_str());
  BoundsReport report = report_bounds(used_vertices(mesh.geometry), o.mesh);
  if (o.json)
    std::printf("%s\n", to_json(report, o.mesh).dump(2).c_str());
  else
    print_text(report, o.mesh);
}

}  // namespace

void add_bounds_command(CLI::App& app) {
  auto options = std::make_shared<BoundsOptions>();
  CLI::App* cmd = app.add_subcommand("bounds", "Print every bounding volume of a mesh (AABB, OBB, k-DOPs, spheres)");
  cmd->add_option("MESH", options->mesh, "Mesh file (.obj, .ply, .stl)")->required();
  cmd->add_flag("--json", options->json, "Print JSON instead of a table");
  cmd->callback([options] { run_bounds(*options); });
}

}  // namespace rtcl::cli
