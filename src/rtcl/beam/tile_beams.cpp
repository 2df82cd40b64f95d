#include "rtcl/beam/tile_beams.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "rtcl/error.hpp"

namespace rtcl::beam {

namespace {

struct Candidate {
  double key;
  std::uint32_t prim, polygon;
};

struct Box2 {
  glm::dvec2 lo{INFINITY}, hi{-INFINITY};
};
Box2 box_of(const std::vector<glm::dvec2>& v) {
  Box2 b;
  for (const glm::dvec2& p : v) {
    b.lo = glm::min(b.lo, p);
    b.hi = glm::max(b.hi, p);
  }
  return b;
}

// The candidate record of polygon p for a beam, or none.
bool candidate(const ScreenPolygon& sp, const Convex& section, double min_area, double* key) {
  Convex part = intersect(Convex{sp.v}, section);
  if (part.v.size() < 3 || signed_area(part.v) < min_area) return false;
  *key = -INFINITY;
  for (const glm::dvec2& v : part.v) *key = std::max(*key, sp.inv_depth.x * v.x + sp.inv_depth.y * v.y + sp.inv_depth.z);
  return true;
}

void push_beam(BeamSet& set, const Convex& section, std::vector<Candidate>& list) {
  if (section.v.size() < 3 || section.v.size() > RTCL_BEAM_PIECE_VERTS)
    throw Error("beam: a beam's cross-section has " + std::to_string(section.v.size()) + " vertices (3 .. " +
                std::to_string(RTCL_BEAM_PIECE_VERTS) + ")");
  std::sort(list.begin(), list.end(), [](const Candidate& a, const Candidate& b) {
    return a.key != b.key ? a.key > b.key : a.prim < b.prim;
  });
  Beam b{};
  Box2 box = box_of(section.v);
  b.x0 = static_cast<float>(std::floor(box.lo.x));
  b.y0 = static_cast<float>(std::floor(box.lo.y));
  b.vertex_count = static_cast<rtcl_u32>(section.v.size());
  for (std::size_t k = 0; k < section.v.size(); ++k) {
    b.x[k] = static_cast<float>(section.v[k].x);
    b.y[k] = static_cast<float>(section.v[k].y);
  }
  b.first = static_cast<rtcl_u32>(set.candidates.size());
  b.count = static_cast<rtcl_u32>(list.size());
  for (const Candidate& c : list) set.candidates.push_back(c.polygon);
  set.beams.push_back(b);
}

}  // namespace

void add_beam(BeamSet& set, const Convex& section, const std::vector<ScreenPolygon>& polygons,
              std::span<const std::uint32_t> candidates) {
  const double min_area = beam_min_area_fraction * signed_area(section.v);
  Box2 box = box_of(section.v);
  std::vector<Candidate> list;
  for (std::uint32_t p : candidates) {
    Box2 pb = box_of(polygons[p].v);
    if (pb.hi.x < box.lo.x || box.hi.x < pb.lo.x || pb.hi.y < box.lo.y || box.hi.y < pb.lo.y) continue;
    double key;
    if (candidate(polygons[p], section, min_area, &key)) list.push_back({key, polygons[p].prim, p});
  }
  push_beam(set, section, list);
}

BeamSet tile_beams(const std::vector<ScreenPolygon>& polygons, std::uint32_t width, std::uint32_t height,
                   std::uint32_t tile_px) {
  BeamSet set;
  set.tile_px = tile_px;
  set.columns = (width + tile_px - 1) / tile_px;
  set.rows = (height + tile_px - 1) / tile_px;
  std::vector<std::vector<Candidate>> lists(std::size_t(set.columns) * set.rows);
  auto section_of = [&](std::uint32_t tx, std::uint32_t ty) {
    double x0 = double(tx) * tile_px, y0 = double(ty) * tile_px;
    return rectangle(x0, y0, std::min<double>(x0 + tile_px, width), std::min<double>(y0 + tile_px, height));
  };
  for (std::uint32_t p = 0; p < polygons.size(); ++p) {
    Box2 b = box_of(polygons[p].v);
    auto first = [&](double c, std::uint32_t n) {
      return static_cast<std::uint32_t>(std::clamp(std::floor(c / tile_px), 0.0, double(n - 1)));
    };
    for (std::uint32_t ty = first(b.lo.y, set.rows); ty <= first(b.hi.y, set.rows); ++ty)
      for (std::uint32_t tx = first(b.lo.x, set.columns); tx <= first(b.hi.x, set.columns); ++tx) {
        Convex section = section_of(tx, ty);
        double key;
        if (candidate(polygons[p], section, beam_min_area_fraction * signed_area(section.v), &key))
          lists[std::size_t(ty) * set.columns + tx].push_back({key, polygons[p].prim, p});
      }
  }
  for (std::uint32_t ty = 0; ty < set.rows; ++ty)
    for (std::uint32_t tx = 0; tx < set.columns; ++tx)
      push_beam(set, section_of(tx, ty), lists[std::size_t(ty) * set.columns + tx]);
  return set;
}

}  // namespace rtcl::beam
