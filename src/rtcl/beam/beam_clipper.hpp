// Beam clipping on the OpenCL device (kernels/render/beam_clip.cl): all beams
// of a set (the tiles of the screen, or one level of the beam tree) in one
// launch, one work-item per beam.
#pragma once

#include <cstdint>
#include <vector>

#include "rtcl/beam/beam_clip_host.hpp"
#include "rtcl/beam/beam_layouts.hpp"
#include "rtcl/beam/screen_space.hpp"
#include "rtcl/beam/tile_beams.hpp"
#include "rtcl/device.hpp"

namespace rtcl::beam {

// The float kernel drops pieces below this fraction of the beam's area:
// float rounding of beam-local coordinates (<= the beam's size, 2^-24
// relative) makes areas uncertain by about 1e-6 of the beam's; far below any
// visible coverage.
inline constexpr float device_min_area_fraction = 1e-6f;

// A beam over a limit is cut into quarters while its bounding box is at
// least this wide (pixels).
inline constexpr double min_split_px = 1.0 / 64.0;

struct DeviceClipStats {
  double clip_ms = 0.0;             // device time of the kernels (0 without profiling)
  std::size_t fragments = 0;        // convex fragment pieces written
  std::size_t launches = 0;         // one per set of beams, plus one per fragment buffer that had to grow
  std::size_t split_beams = 0;      // quarters clipped again (beams over a limit, cut in four)
};

// Fragments as the device wrote them, sorted by (beam, seq): the host
// reference's order, except for a beam that needed more than
// RTCL_BEAM_MAX_PIECES pieces or a piece of more than RTCL_BEAM_PIECE_VERTS
// vertices: it is cut into the four quarters of its bounding box (each with
// the candidates that meet it, exactly), which are clipped again, and its
// fragments are theirs, quarter by quarter. Throws Error naming the beam
// and the limit when a piece below min_split_px still goes over, and when
// the fragments do not fit in the device's memory (after one retry with a
// buffer of the size counted).
std::vector<BeamFragment> clip_beams_device(const Device& device, const std::vector<ScreenPolygon>& polygons,
                                            const BeamSet& beams, DepthOrder order,
                                            DeviceClipStats* stats = nullptr);

}  // namespace rtcl::beam
