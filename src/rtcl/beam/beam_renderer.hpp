// `rtcl render --method beam`: beam tracing of the primary visibility
// (Heckbert and Hanrahan 1984). Tile beams (8x8 pixels) are clipped on the
// device (beam_clipper.hpp); every fragment is rasterised with exact
// coverage (the area of fragment ∩ pixel square, in double on the host) and
// shaded once per (fragment, pixel) at the point of its plane seen through
// the centroid of that area, with the local Phong terms of the ray tracer
// (kernels/render/shade.cl: emission, ambient, Lambert, Phong highlight) and
// point lights whose shadows are shadow rays through the structure `accel`
// on the device. The pixel is the coverage-weighted sum, plus the
// background times the uncovered fraction: anti-aliased visibility without
// samples. Reflection and refraction beams are not traced: a mirror or glass
// surface shows its local terms only (said in the summary line).
#pragma once

#include <cstdint>
#include <string>

#include "rtcl/beam/beam_clip_host.hpp"
#include "rtcl/cl/device.hpp"
#include "rtcl/render/image.hpp"
#include "rtcl/scene/scene.hpp"

namespace rtcl::beam {

struct BeamSettings {
  std::uint32_t width = 512, height = 512;
  DepthOrder order = DepthOrder::exact;
  std::string accel = "bvh";  // structure of the shadow rays
};

struct BeamStats {
  std::size_t polygons = 0;       // screen polygons after near and screen clipping
  std::size_t tiles = 0;          // tile beams
  std::size_t candidates = 0;     // (tile, polygon) pairs walked
  std::size_t fragments = 0;      // convex fragment pieces from the device
  std::size_t pixel_pieces = 0;   // (fragment, pixel) pairs shaded
  std::size_t shadow_rays = 0;
  double clip_ms = 0.0;           // device time of the clipping kernel (0 without profiling)
  double render_ms = 0.0;         // wall clock of the whole render
};

// Throws Error naming scene.source when the scene has spheres (beam tracing
// takes polygons only) or an area light (point lights only).
void check_beam_scene(const Scene& scene);

Image render_beam(const Device& device, const Scene& scene, const BeamSettings& settings, BeamStats* stats = nullptr);

// Per pixel (row-major), the coverage of every visible triangle id by the
// fragments of the device walk: for tests and benchmarks.
struct CoverageEntry {
  std::uint32_t pixel, prim;
  double area;  // square pixels, in (0, 1]
};
std::vector<CoverageEntry> beam_coverage(const Device& device, const Scene& scene, const BeamSettings& settings);

}  // namespace rtcl::beam
