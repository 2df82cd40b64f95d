// Beams and their candidate polygons in walking order. The viewing beam is
// split into tile beams (prisms over tile x tile pixel squares); a reflected
// or refracted beam is the prism over a fragment of a mirror or a
// transmissive polygon. A polygon is a candidate of a beam when its
// projection meets the beam's cross-section with positive area (exact, in
// double); tile beams test the polygons whose bounding box meets the tile,
// the other beams those the BVH frustum cull leaves (beam_cull.hpp).
// Walking order: descending key, the largest inverse depth
// 1/s of the polygon's part inside the beam (its nearest point there), ties
// by triangle id (a beam's candidates all come from one world, so the order
// does not depend on when their screen polygons were made).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "rtcl/beam/beam_layouts.hpp"
#include "rtcl/beam/polygon2d.hpp"
#include "rtcl/beam/screen_space.hpp"

namespace rtcl::beam {

struct BeamSet {
  std::vector<Beam> beams;
  std::vector<std::uint32_t> candidates;  // indexes into the polygon list, per beam [first, first + count)
  std::uint32_t tile_px = 8, columns = 0, rows = 0;  // of tile beams: beams[row * columns + column]
};

// Appends the beam over `cross_section` (convex, counter-clockwise, 3 ..
// RTCL_BEAM_PIECE_VERTS vertices, pixels) with its candidates among
// polygons[i], i in `candidates` (those meeting the cross-section with
// positive area, exact). Throws Error when the cross-section has too many
// vertices.
void add_beam(BeamSet& set, const Convex& cross_section, const std::vector<ScreenPolygon>& polygons,
              std::span<const std::uint32_t> candidates);

// The tile beams of a width x height screen over all polygons, row by row;
// the last column and row may be narrower.
BeamSet tile_beams(const std::vector<ScreenPolygon>& polygons, std::uint32_t width, std::uint32_t height,
                   std::uint32_t tile_px = 8);

}  // namespace rtcl::beam
