// Beam clipping of beams on the host in double precision: the reference
// the device kernel (kernels/render/beam_clip.cl) is tested against, the same
// walk in the same order. Per tile beam (lecture, 反射光束跟踪过程（2）): walk
// the candidates front to back; fragment = beam ∩ polygon; record it;
// beam −= fragment; stop when the beam is empty or the list is exhausted.
#pragma once

#include <cstdint>
#include <vector>

#include "rtcl/beam/polygon2d.hpp"
#include "rtcl/beam/screen_space.hpp"
#include "rtcl/beam/tile_beams.hpp"

namespace rtcl::beam {

enum class DepthOrder {
  // The lecture's walk alone: the first candidate in key order takes all of
  // its projection the beam still holds. Wrong where a later candidate is in
  // front of an earlier one over part of it (interpenetrating or cyclically
  // overlapping polygons, and polygons whose nearest points mislead the
  // key, e.g. a box standing on a floor).
  key,
  // The walk, plus: a fragment gives up the part where a later candidate's
  // plane is nearer (1/s of two planes differs by an affine function of
  // screen position, so "Q in front of P" is a half-plane): the visible
  // region exactly, for any arrangement of planar polygons.
  exact,
};

struct HostFragment {
  std::uint32_t beam = 0, polygon = 0;  // indexes into BeamSet::beams and the polygon list
  Convex piece;                         // pixels
};

// The beam's cross-section as stored (float vertices, exactly in double).
Convex cross_section(const Beam& beam);

// Fragments in the kernel's output order (per beam: walking order, then
// beam piece order, then fragment piece order). Pieces below
// beam_min_area_fraction of the beam's area are dropped.
std::vector<HostFragment> clip_beams_host(const std::vector<ScreenPolygon>& polygons, const BeamSet& beams,
                                          DepthOrder order);

}  // namespace rtcl::beam
