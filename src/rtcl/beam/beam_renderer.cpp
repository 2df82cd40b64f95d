#include "rtcl/beam/beam_renderer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <unordered_map>
#include <utility>

#include "rtcl/accel.hpp"
#include "rtcl/accel/bvh.hpp"
#include "rtcl/beam/beam_cull.hpp"
#include "rtcl/beam/beam_clipper.hpp"
#include "rtcl/beam/mirror.hpp"
#include "rtcl/beam/polygon2d.hpp"
#include "rtcl/beam/refraction.hpp"
#include "rtcl/beam/screen_space.hpp"
#include "rtcl/beam/tile_beams.hpp"
#include "rtcl/error.hpp"
#include "rtcl/render/camera.hpp"

namespace rtcl::beam {

namespace {

using glm::dvec2;
using glm::dvec3;

// One fragment's share of one pixel.
struct PixelPiece {
  std::uint32_t pixel, polygon, world;
  double area;
  dvec2 centroid;
  dvec3 weight;  // product of kr down the beam tree
};

dvec2 centroid(const Convex& c, double a) {
  dvec2 sum(0.0);
  const std::size_t n = c.v.size();
  for (std::size_t i = 0; i < n; ++i) {
    const dvec2 &p = c.v[i], &q = c.v[(i + 1) % n];
    double w = p.x * q.y - q.x * p.y;
    sum += w * (p + q);
  }
  return sum / (6.0 * a);
}

// One world of the beam tree: the scene moved by the product of the
// transforms of the interfaces above it (M_r of a mirror, M_t of a
// refracting polygon), clipped to the far side of the last interface
// (`keep`, in the world's coordinates). Its screen polygons are made on
// demand: polygon_of maps a triangle to its index in Visible::polygons, or
// to -1 when it is not seen in this world.
struct World {
  glm::dmat4 to_virtual{1.0}, to_real{1.0};
  bool clipped = false;
  glm::dvec4 keep{0.0};
  std::unordered_map<std::uint32_t, std::int64_t> polygon_of;
};

struct BeamInfo {
  std::uint32_t world;
  dvec3 weight;
  std::uint32_t depth;
};

struct Visible {
  ScreenSpace screen;
  std::vector<ScreenPolygon> polygons;
  std::vector<World> worlds;
  std::vector<PixelPiece> pieces;
  std::vector<dvec3> background_weight;  // per pixel: weighted area of beams that meet nothing
  BeamStats stats;
};

Convex piece_of(const BeamFragment& f) {
  Convex c;
  for (std::uint32_t k = 0; k < f.count; ++k) c.v.push_back({f.x[k], f.y[k]});
  return c;
}

// Calls out(pixel, area, centroid) for every pixel square `piece` meets.
template <class Out>
void rasterise(const Convex& piece, std::uint32_t width, std::uint32_t height, Out out) {
  dvec2 lo(INFINITY), hi(-INFINITY);
  for (const dvec2& p : piece.v) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  auto px0 = std::uint32_t(std::clamp(std::floor(lo.x), 0.0, double(width - 1)));
  auto px1 = std::uint32_t(std::clamp(std::floor(hi.x), 0.0, double(width - 1)));
  auto py0 = std::uint32_t(std::clamp(std::floor(lo.y), 0.0, double(height - 1)));
  auto py1 = std::uint32_t(std::clamp(std::floor(hi.y), 0.0, double(height - 1)));
  for (std::uint32_t y = py0; y <= py1; ++y)
    for (std::uint32_t x = px0; x <= px1; ++x) {
      Convex c = intersect(piece, rectangle(x, y, x + 1.0, y + 1.0));
      if (c.v.size() < 3) continue;
      double a = signed_area(c.v);
      if (a > 0.0) out(y * width + x, a, centroid(c, a));
    }
}

// The builder of the beam tree below the viewing beam: worlds, their
// polygons and the candidates of each beam.
class Tree {
 public:
  Tree(Visible& v, const Geometry& g, const BeamSettings& s) : v_(v), g_(g), s_(s) {}

  // Triangle prim's screen polygon in world w (made on first use), or -1.
  std::int64_t polygon_in(std::uint32_t w, std::uint32_t prim) {
    World& wd = v_.worlds[w];
    auto it = wd.polygon_of.find(prim);
    if (it != wd.polygon_of.end()) return it->second;
    ScreenPolygon sp;
    std::int64_t index = -1;
    if (screen_polygon(v_.screen, g_, prim, wd.to_virtual, wd.clipped ? &wd.keep : nullptr, keep_margin(), &sp)) {
      index = std::int64_t(v_.polygons.size());
      v_.polygons.push_back(std::move(sp));
    }
    wd.polygon_of.emplace(prim, index);
    return index;
  }

  // The world seen through the fragment of triangle prim in world `parent`:
  // `bend` maps the new world's real points to the parent's real points on
  // the straight continuation of its rays (M_r, M_t).
  std::uint32_t add_world(std::uint32_t parent, std::uint32_t prim, const glm::dmat4& bend) {
    World child;
    const World& p = v_.worlds[parent];
    child.to_virtual = p.to_virtual * bend;
    child.to_real = glm::inverse(child.to_virtual);
    // The interface in the parent's (and, fixed by `bend`, the child's)
    // coordinates; keep its side away from the eye.
    glm::dvec4 L = glm::transpose(p.to_real) * real_plane(prim);
    L /= glm::length(glm::dvec3(L));
    child.clipped = true;
    child.keep = glm::dot(L, glm::dvec4(v_.screen.frame.origin, 1.0)) > 0.0 ? -L : L;
    v_.worlds.push_back(std::move(child));
    return std::uint32_t(v_.worlds.size() - 1);
  }

  // The plane of triangle prim in the real world, unit normal along (b - a) x (c - a).
  glm::dvec4 real_plane(std::uint32_t prim) const {
    const glm::uvec3& t = g_.triangles[prim];
    return plane_through(dvec3(g_.vertices[t.x]), dvec3(g_.vertices[t.y]), dvec3(g_.vertices[t.z]));
  }

  // Appends the beam over `section` in world w with its candidates: the
  // triangles the BVH frustum cull keeps (CandidateCull::bvh) or all of
  // them (CandidateCull::all), then the exact overlap test.
  void add(BeamSet& set, const Convex& section, std::uint32_t w) {
    auto start = std::chrono::steady_clock::now();
    prims_.clear();
    if (s_.cull == CandidateCull::bvh) {
      if (bvh_.empty()) bvh_ = build_binary_bvh(g_);
      const World& wd = v_.worlds[w];
      cull(bvh_, beam_frustum(v_.screen, section, wd.to_virtual, wd.clipped ? &wd.keep : nullptr), prims_);
    } else {
      for (std::uint32_t t = 0; t < g_.triangles.size(); ++t) prims_.push_back(t);
    }
    std::vector<std::uint32_t> polygons;
    for (std::uint32_t prim : prims_) {
      std::int64_t i = polygon_in(w, prim);
      if (i >= 0) polygons.push_back(std::uint32_t(i));
    }
    add_beam(set, section, v_.polygons, polygons);
    v_.stats.cull_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }

 private:
  double keep_margin() const { return 1e-9 * v_.screen.near / near_fraction; }

  Visible& v_;
  const Geometry& g_;
  const BeamSettings& s_;
  BuildTree bvh_;
  std::vector<std::uint32_t> prims_;
};

// A child beam of a fragment: its world and weight.
struct Child {
  std::uint32_t world;
  dvec3 weight;
};

// Refraction at a fragment of a transmissive polygon (plane: its real-world
// plane), decided by the fragment's central ray, from the eye through the
// centroid of its cross-section: F, the ray tracer's Fresnel reflectance
// (kernels/render/shade.cl; 1 under total internal reflection), and M_t
// (none under total internal reflection).
struct Refraction {
  double F = 1.0;
  std::optional<glm::dmat4> bend;
};
Refraction refraction_at(const ScreenSpace& screen, const World& world, const ScreenPolygon& polygon,
                         const glm::dvec4& plane, const dvec2& centre, double ior) {
  const dvec3 eye = screen.frame.origin;
  const dvec3 through = unproject(screen, polygon.inv_depth, centre);
  const dvec3 incident = glm::normalize(glm::dmat3(world.to_real) * (through - eye));
  double cos_i = -glm::dot(incident, dvec3(plane));
  const double eta = cos_i > 0.0 ? 1.0 / ior : ior;  // arriving on the normal's side: entering
  cos_i = std::abs(cos_i);
  const double sin2_t = eta * eta * (1.0 - cos_i * cos_i);
  Refraction r;
  if (!(sin2_t < 1.0)) return r;
  r.bend = refraction_matrix(plane, incident, eta);
  if (r.bend) r.F = fresnel_dielectric(cos_i, std::sqrt(1.0 - sin2_t), eta);
  return r;
}

// The beam tree, level by level: one device launch per level.
Visible visible_pieces(const Device& device, const SceneDescription& scene, const FlatScene& flat, const BeamSettings& s,
                       bool primary_only = false) {
  Visible v;
  const Geometry& g = flat.geometry;
  v.screen = screen_space(camera_frame(scene.camera, s.width, s.height), s.width, s.height, g);
  v.polygons = screen_polygons(v.screen, g);
  v.worlds.emplace_back();
  for (std::size_t i = 0; i < v.polygons.size(); ++i) v.worlds[0].polygon_of.emplace(v.polygons[i].prim, std::int64_t(i));
  Tree tree(v, g, s);
  v.background_weight.assign(std::size_t(s.width) * s.height, dvec3(0.0));
  BeamSet level = tile_beams(v.polygons, s.width, s.height);
  std::vector<BeamInfo> info(level.beams.size(), BeamInfo{0, dvec3(1.0), 0});
  v.stats.polygons = v.polygons.size();
  v.stats.tiles = level.beams.size();
  // Every beam's area starts as background; each fragment takes its share back.
  for (const Beam& b : level.beams)
    rasterise(cross_section(b), s.width, s.height,
              [&](std::uint32_t px, double a, dvec2) { v.background_weight[px] += a * dvec3(1.0); });
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mirror_world;  // (parent world, mirror prim)
  auto heavy = [&](const dvec3& w) {
    double m = std::max({w.x, w.y, w.z});
    return m > 0.0 && m >= double(s.min_weight);
  };
  while (!level.beams.empty()) {
    ++v.stats.levels;
    v.stats.candidates += level.candidates.size();
    DeviceClipStats cs;
    std::vector<BeamFragment> frags = clip_beams_device(device, v.polygons, level, s.order, &cs);
    v.stats.fragments += frags.size();
    v.stats.clip_ms += cs.clip_ms;
    BeamSet next;
    std::vector<BeamInfo> next_info;
    for (const BeamFragment& f : frags) {
      const BeamInfo bi = info[f.beam];
      const std::uint32_t prim = v.polygons[f.polygon].prim;
      Convex piece = piece_of(f);
      rasterise(piece, s.width, s.height, [&](std::uint32_t px, double a, dvec2 c) {
        v.pieces.push_back({px, f.polygon, bi.world, a, c, bi.weight});
        v.background_weight[px] -= a * bi.weight;
      });
      const Material& m = scene.materials[flat.material[prim]];
      const double area = signed_area(piece.v);  // 0 for a piece collinear in double: no child
      if (primary_only || bi.depth >= s.max_depth || !(area > 0.0)) continue;
      // Children with the ray tracer's weights: reflected kr + kt F,
      // refracted kt (1 - F).
      std::vector<Child> children;
      dvec3 reflected = bi.weight * dvec3(m.kr);
      if (m.transmissive()) {
        Refraction r = refraction_at(v.screen, v.worlds[bi.world], v.polygons[f.polygon], tree.real_plane(prim),
                                     centroid(piece, area), double(m.ior));
        if (!r.bend) ++v.stats.total_internal_reflections;
        const dvec3 refracted = bi.weight * dvec3(m.kt) * (1.0 - r.F);
        if (r.bend && heavy(refracted)) {
          children.push_back({tree.add_world(bi.world, prim, *r.bend), refracted});
          ++v.stats.refracted_beams;
        }
        reflected += bi.weight * dvec3(m.kt) * r.F;
      }
      if (heavy(reflected)) {
        auto key = std::make_pair(bi.world, prim);
        auto it = mirror_world.find(key);
        if (it == mirror_world.end())
          it = mirror_world.emplace(key, tree.add_world(bi.world, prim, reflection_matrix(tree.real_plane(prim)))).first;
        children.push_back({it->second, reflected});
        ++v.stats.reflected_beams;
      }
      for (const Child& c : children) {
        tree.add(next, piece, c.world);
        next_info.push_back(BeamInfo{c.world, c.weight, bi.depth + 1});
        rasterise(piece, s.width, s.height,
                  [&](std::uint32_t px, double a, dvec2) { v.background_weight[px] += a * c.weight; });
      }
    }
    level = std::move(next);
    info = std::move(next_info);
  }
  v.stats.pixel_pieces = v.pieces.size();
  return v;
}

double max_abs3(const dvec3& p) { return std::max(std::abs(p.x), std::max(std::abs(p.y), std::abs(p.z))); }

}  // namespace

void check_beam_scene(const SceneDescription& scene) {
  if (!scene.spheres.empty())
    throw Error(scene.source + ": --method beam traces polygons only, and the scene has " +
                std::to_string(scene.spheres.size()) + " sphere(s); remove them or use --method ray");
  for (std::size_t i = 0; i < scene.lights.size(); ++i)
    if (scene.lights[i].area())
      throw Error(scene.source + ": light " + std::to_string(i) +
                  " is an area light; --method beam shades with point lights only (use --method ray)");
  for (const SceneMesh& mesh : scene.meshes)
    if (mesh.end_transform)
      throw Error(mesh.motion_key + ": a moving object; --method beam traces a static scene (use --method ray)");
  for (const Material& m : scene.materials)
    if (m.glossy())
      throw Error(scene.source + ": material '" + m.name +
                  "' is glossy; --method beam traces mirror reflection and refraction only (use --method ray)");
}

std::vector<CoverageEntry> beam_coverage(const Device& device, const SceneDescription& scene, const BeamSettings& settings) {
  check_beam_scene(scene);
  validate(scene);
  FlatScene flat = flatten(scene);
  Visible v = visible_pieces(device, scene, flat, settings, true);
  std::vector<CoverageEntry> out;
  for (const PixelPiece& p : v.pieces) out.push_back({p.pixel, v.polygons[p.polygon].prim, p.area});
  return out;
}

Image render_beam(const Device& device, const SceneDescription& scene, const BeamSettings& settings, BeamStats* stats) {
  auto start = std::chrono::steady_clock::now();
  check_beam_scene(scene);
  validate(scene);
  FlatScene flat = flatten(scene);
  validate(flat.geometry);
  Visible v = visible_pieces(device, scene, flat, settings);
  const Geometry& g = flat.geometry;
  const std::vector<Light>& lights = scene.lights;

  // Shading points and their shadow rays (origin offset as in shade.cl).
  struct Point {
    dvec3 p, n, view;  // n faces the viewer; view: unit direction from the eye
    double offset;
  };
  std::vector<Point> points(v.pieces.size());
  std::vector<Ray> shadow;
  std::vector<std::uint32_t> shadow_of;  // piece * lights + light
  for (std::size_t i = 0; i < v.pieces.size(); ++i) {
    const PixelPiece& pp = v.pieces[i];
    const ScreenPolygon& sp = v.polygons[pp.polygon];
    const glm::uvec3& tri = g.triangles[sp.prim];
    dvec3 a(g.vertices[tri.x]), b(g.vertices[tri.y]), c(g.vertices[tri.z]);
    dvec3 e1 = b - a, e2 = c - a;
    Point& pt = points[i];
    const World& wd = v.worlds[pp.world];
    dvec3 pv = unproject(v.screen, sp.inv_depth, pp.centroid);  // in the beam's (virtual) world
    pt.p = dvec3(wd.to_real * glm::dvec4(pv, 1.0));
    pt.view = glm::normalize(glm::dmat3(wd.to_real) * (pv - v.screen.frame.origin));
    dvec3 ng = glm::normalize(glm::cross(e1, e2));
    pt.n = glm::dot(ng, pt.view) < 0.0 ? ng : -ng;
    double extent = std::max(max_abs3(e1), max_abs3(e2));
    pt.offset = double(std::numeric_limits<float>::epsilon()) * (3.0 * max_abs3(pt.p) + 16.0 * extent);
    dvec3 above = pt.p + pt.offset * pt.n;
    for (std::uint32_t l = 0; l < lights.size(); ++l) {
      dvec3 lp(lights[l].position);
      if (!(glm::dot(pt.n, lp - pt.p) > 0.0)) continue;
      dvec3 d = lp - above;
      Ray r{};
      r.ox = float(above.x), r.oy = float(above.y), r.oz = float(above.z);
      r.dx = float(d.x), r.dy = float(d.y), r.dz = float(d.z);
      r.tmin = 0.0f;
      r.tmax = 1.0f - 1e-4f;  // RTCL_SHADOW_SHORTEN
      shadow.push_back(r);
      shadow_of.push_back(std::uint32_t(i * lights.size() + l));
    }
  }
  std::vector<std::uint8_t> lit(v.pieces.size() * lights.size(), 0);
  if (!shadow.empty()) {
    std::unique_ptr<Accel> accel = make_accel(device, settings.accel, g);
    cl::Buffer rays = device.upload(shadow.data(), shadow.size() * sizeof(Ray), "beam shadow rays");
    cl::Buffer hits = device.allocate(shadow.size() * sizeof(Hit), "beam shadow hits");
    accel->trace(Query::any, rays, hits, shadow.size()).wait();
    std::vector<Hit> h(shadow.size());
    check_cl(device.queue().enqueueReadBuffer(hits, CL_TRUE, 0, h.size() * sizeof(Hit), h.data(), nullptr, nullptr),
             "clEnqueueReadBuffer(beam shadow hits)");
    for (std::size_t k = 0; k < h.size(); ++k) lit[shadow_of[k]] = h[k].prim < 0;
  }

  Image img;
  img.width = settings.width;
  img.height = settings.height;
  std::vector<double> rgb(std::size_t(img.width) * img.height * 3, 0.0);
  for (std::size_t i = 0; i < v.pieces.size(); ++i) {
    const PixelPiece& pp = v.pieces[i];
    const Point& pt = points[i];
    const Material& m = scene.materials[flat.material[v.polygons[pp.polygon].prim]];
    dvec3 L = dvec3(m.emission) + dvec3(scene.ambient) * dvec3(m.ambient);
    for (std::uint32_t l = 0; l < lights.size(); ++l) {
      if (!lit[i * lights.size() + l]) continue;
      dvec3 ld = glm::normalize(dvec3(lights[l].position) - pt.p);
      double cos_l = glm::dot(pt.n, ld);
      dvec3 f = dvec3(m.diffuse) * cos_l;
      if (std::max({m.specular.x, m.specular.y, m.specular.z}) > 0.0f) {
        dvec3 mirror = 2.0 * cos_l * pt.n - ld;
        double rv = std::max(glm::dot(mirror, -pt.view), 0.0);
        f += dvec3(m.specular) * (m.shininess > 0.0f ? std::pow(rv, double(m.shininess)) : 1.0);
      }
      L += dvec3(lights[l].color) * double(lights[l].intensity) * f;
    }
    for (int k = 0; k < 3; ++k) rgb[pp.pixel * 3 + k] += pp.area * pp.weight[k] * L[k];
  }
  img.rgb.resize(rgb.size());
  for (std::size_t p = 0; p < v.background_weight.size(); ++p)
    for (int k = 0; k < 3; ++k)
      img.rgb[p * 3 + k] =
          float(rgb[p * 3 + k] + std::max(0.0, v.background_weight[p][k]) * double(scene.background[k]));
  BeamStats st = v.stats;
  st.shadow_rays = shadow.size();
  st.render_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (stats) *stats = st;
  return img;
}

}  // namespace rtcl::beam
