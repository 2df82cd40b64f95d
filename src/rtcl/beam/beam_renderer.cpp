#include "rtcl/beam/beam_renderer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "rtcl/accel/accel.hpp"
#include "rtcl/beam/beam_clipper.hpp"
#include "rtcl/beam/polygon2d.hpp"
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
  std::uint32_t pixel, polygon;
  double area;
  dvec2 centroid;
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

struct Visible {
  ScreenSpace screen;
  std::vector<ScreenPolygon> polygons;
  std::vector<PixelPiece> pieces;
  BeamStats stats;
};

// Exact coverage: each fragment piece against the pixel squares of its box.
Visible visible_pieces(const Device& device, const Scene& scene, const FlatScene& flat, const BeamSettings& s) {
  Visible v;
  v.screen = screen_space(camera_frame(scene.camera, s.width, s.height), s.width, s.height, flat.geometry);
  v.polygons = screen_polygons(v.screen, flat.geometry);
  TileBeams tiles = tile_beams(v.polygons, s.width, s.height);
  DeviceClipStats cs;
  std::vector<BeamFragment> frags = clip_beams_device(device, v.polygons, tiles, s.order, &cs);
  v.stats.polygons = v.polygons.size();
  v.stats.tiles = tiles.tiles.size();
  v.stats.candidates = tiles.candidates.size();
  v.stats.fragments = frags.size();
  v.stats.clip_ms = cs.clip_ms;
  for (const BeamFragment& f : frags) {
    const BeamTile& t = tiles.tiles[f.tile];
    Convex piece;
    for (std::uint32_t k = 0; k < f.count; ++k) piece.v.push_back({f.x[k], f.y[k]});
    dvec2 lo(INFINITY), hi(-INFINITY);
    for (const dvec2& p : piece.v) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    // Within its tile: fragments never leave it (float rounding clamped).
    auto px0 = std::uint32_t(std::clamp(std::floor(lo.x), double(t.x0), double(t.x0 + t.w - 1)));
    auto px1 = std::uint32_t(std::clamp(std::floor(hi.x), double(t.x0), double(t.x0 + t.w - 1)));
    auto py0 = std::uint32_t(std::clamp(std::floor(lo.y), double(t.y0), double(t.y0 + t.h - 1)));
    auto py1 = std::uint32_t(std::clamp(std::floor(hi.y), double(t.y0), double(t.y0 + t.h - 1)));
    for (std::uint32_t y = py0; y <= py1; ++y)
      for (std::uint32_t x = px0; x <= px1; ++x) {
        Convex c = intersect(piece, rectangle(x, y, x + 1.0, y + 1.0));
        if (c.v.size() < 3) continue;
        double a = signed_area(c.v);
        if (!(a > 0.0)) continue;
        v.pieces.push_back({y * s.width + x, f.polygon, a, centroid(c, a)});
      }
  }
  v.stats.pixel_pieces = v.pieces.size();
  return v;
}

double max_abs3(const dvec3& p) { return std::max(std::abs(p.x), std::max(std::abs(p.y), std::abs(p.z))); }

}  // namespace

void check_beam_scene(const Scene& scene) {
  if (!scene.spheres.empty())
    throw Error(scene.source + ": --method beam traces polygons only, and the scene has " +
                std::to_string(scene.spheres.size()) + " sphere(s); remove them or use --method ray");
  for (std::size_t i = 0; i < scene.lights.size(); ++i)
    if (scene.lights[i].area())
      throw Error(scene.source + ": light " + std::to_string(i) +
                  " is an area light; --method beam shades with point lights only (use --method ray)");
}

std::vector<CoverageEntry> beam_coverage(const Device& device, const Scene& scene, const BeamSettings& settings) {
  check_beam_scene(scene);
  validate(scene);
  FlatScene flat = flatten(scene);
  Visible v = visible_pieces(device, scene, flat, settings);
  std::vector<CoverageEntry> out;
  for (const PixelPiece& p : v.pieces) out.push_back({p.pixel, v.polygons[p.polygon].prim, p.area});
  return out;
}

Image render_beam(const Device& device, const Scene& scene, const BeamSettings& settings, BeamStats* stats) {
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
    pt.p = unproject(v.screen, sp.inv_depth, pp.centroid);
    pt.view = glm::normalize(pt.p - v.screen.frame.origin);
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
  std::vector<double> rgb(std::size_t(img.width) * img.height * 3, 0.0), covered(std::size_t(img.width) * img.height, 0.0);
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
    for (int k = 0; k < 3; ++k) rgb[pp.pixel * 3 + k] += pp.area * L[k];
    covered[pp.pixel] += pp.area;
  }
  img.rgb.resize(rgb.size());
  for (std::size_t p = 0; p < covered.size(); ++p)
    for (int k = 0; k < 3; ++k)
      img.rgb[p * 3 + k] =
          float(rgb[p * 3 + k] + std::max(0.0, 1.0 - covered[p]) * double(scene.background[k]));
  BeamStats st = v.stats;
  st.shadow_rays = shadow.size();
  st.render_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (stats) *stats = st;
  return img;
}

}  // namespace rtcl::beam
