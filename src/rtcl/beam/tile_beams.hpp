// The screen's viewing beam split into tile beams (prisms over tile x tile
// pixel squares) with their candidate polygons in walking order. Candidates
// are culled in screen space: a polygon is a candidate of a tile when its
// projection meets the tile's square with positive area (exact, in double;
// not the BVH frustum test). Walking order: descending key, the largest
// inverse depth 1/s of the polygon's part inside the tile (its nearest
// point there), ties by polygon index.
#pragma once

#include <cstdint>
#include <vector>

#include "rtcl/beam/beam_layouts.hpp"
#include "rtcl/beam/screen_space.hpp"

namespace rtcl::beam {

struct TileBeams {
  std::uint32_t tile_px = 8, columns = 0, rows = 0;
  std::vector<BeamTile> tiles;            // row by row; the last column and row may be narrower
  std::vector<std::uint32_t> candidates;  // indexes into the polygon list, per tile [first, first + count)
};

TileBeams tile_beams(const std::vector<ScreenPolygon>& polygons, std::uint32_t width, std::uint32_t height,
                     std::uint32_t tile_px = 8);

}  // namespace rtcl::beam
