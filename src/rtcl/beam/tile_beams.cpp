#include "rtcl/beam/tile_beams.hpp"

#include <algorithm>
#include <cmath>

#include "rtcl/beam/polygon2d.hpp"

namespace rtcl::beam {

TileBeams tile_beams(const std::vector<ScreenPolygon>& polygons, std::uint32_t width, std::uint32_t height,
                     std::uint32_t tile_px) {
  TileBeams tb;
  tb.tile_px = tile_px;
  tb.columns = (width + tile_px - 1) / tile_px;
  tb.rows = (height + tile_px - 1) / tile_px;
  struct Candidate {
    double key;
    std::uint32_t polygon;
  };
  std::vector<std::vector<Candidate>> lists(std::size_t(tb.columns) * tb.rows);
  for (std::uint32_t p = 0; p < polygons.size(); ++p) {
    const ScreenPolygon& sp = polygons[p];
    glm::dvec2 lo(INFINITY), hi(-INFINITY);
    for (const glm::dvec2& v : sp.v) {
      lo = glm::min(lo, v);
      hi = glm::max(hi, v);
    }
    auto first = [&](double c, std::uint32_t n) {
      return static_cast<std::uint32_t>(std::clamp(std::floor(c / tile_px), 0.0, double(n - 1)));
    };
    Convex poly{sp.v};
    for (std::uint32_t ty = first(lo.y, tb.rows); ty <= first(hi.y, tb.rows); ++ty)
      for (std::uint32_t tx = first(lo.x, tb.columns); tx <= first(hi.x, tb.columns); ++tx) {
        double x0 = double(tx) * tile_px, y0 = double(ty) * tile_px;
        double x1 = std::min<double>(x0 + tile_px, width), y1 = std::min<double>(y0 + tile_px, height);
        Convex part = intersect(poly, rectangle(x0, y0, x1, y1));
        if (part.v.size() < 3 || signed_area(part.v) < beam_min_area_fraction * (x1 - x0) * (y1 - y0)) continue;
        double key = -INFINITY;
        for (const glm::dvec2& v : part.v)
          key = std::max(key, sp.inv_depth.x * v.x + sp.inv_depth.y * v.y + sp.inv_depth.z);
        lists[std::size_t(ty) * tb.columns + tx].push_back({key, p});
      }
  }
  for (std::uint32_t ty = 0; ty < tb.rows; ++ty)
    for (std::uint32_t tx = 0; tx < tb.columns; ++tx) {
      auto& list = lists[std::size_t(ty) * tb.columns + tx];
      std::sort(list.begin(), list.end(), [](const Candidate& a, const Candidate& b) {
        return a.key != b.key ? a.key > b.key : a.polygon < b.polygon;
      });
      BeamTile t;
      t.x0 = tx * tile_px;
      t.y0 = ty * tile_px;
      t.w = std::min(tile_px, width - t.x0);
      t.h = std::min(tile_px, height - t.y0);
      t.first = static_cast<std::uint32_t>(tb.candidates.size());
      t.count = static_cast<std::uint32_t>(list.size());
      for (const Candidate& c : list) tb.candidates.push_back(c.polygon);
      tb.tiles.push_back(t);
    }
  return tb;
}

}  // namespace rtcl::beam
