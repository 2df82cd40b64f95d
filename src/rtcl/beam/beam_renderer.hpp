// `rtcl render --method beam`: beam tracing (Heckbert and Hanrahan 1984).
// The viewing beam's tiles (8x8 pixels) are clipped on the device
// (beam_clipper.hpp); a fragment on a mirror (kr > 0) starts a reflected
// beam over the fragment in the scene transformed by the mirror's M_r
// (mirror.hpp), clipped to the far side of the mirror; each level of the
// beam tree is one device launch, up to max_depth levels below the viewing
// beam. Every fragment is rasterised with exact coverage (the area of
// fragment ∩ pixel square, in double on the host) and shaded once per
// (fragment, pixel) at the point of its plane seen through the centroid of
// that area (mapped back to the real world), with the local Phong terms of
// the ray tracer (kernels/render/shade.cl: emission, ambient, Lambert, Phong
// highlight) and point lights whose shadows are shadow rays through the
// structure `accel` on the device. Radiance: I = C_d I_d + C_s I_s + Σ C_r
// I_r over the beam tree (C_r: the product of kr down the tree), plus the
// background times each beam's uncovered area. Refraction beams are not
// traced: transmissive materials are refused.
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
  std::uint32_t max_depth = 5;  // reflection levels below the viewing beam (the ray tracer's --depth)
  float min_weight = 1e-3f;     // a reflected beam whose weight's largest component is below this is not traced
  std::string accel = "bvh";  // structure of the shadow rays
};

struct BeamStats {
  std::size_t polygons = 0;       // screen polygons after near and screen clipping
  std::size_t tiles = 0;          // tile beams
  std::size_t reflected_beams = 0;  // beams below the viewing beam, all levels
  std::uint32_t levels = 0;         // beam-tree levels traced (1: the viewing beam only)
  std::size_t candidates = 0;     // (tile, polygon) pairs walked
  std::size_t fragments = 0;      // convex fragment pieces from the device
  std::size_t pixel_pieces = 0;   // (fragment, pixel) pairs shaded
  std::size_t shadow_rays = 0;
  double clip_ms = 0.0;           // device time of the clipping kernels (0 without profiling)
  double render_ms = 0.0;         // wall clock of the whole render
};

// Throws Error naming scene.source when the scene has spheres (beam tracing
// takes polygons only), an area light (point lights only), or a
// transmissive or glossy material (no refraction or glossy beams).
void check_beam_scene(const Scene& scene);

Image render_beam(const Device& device, const Scene& scene, const BeamSettings& settings, BeamStats* stats = nullptr);

// Per pixel (row-major), the coverage of every visible triangle id by the
// fragments of the viewing beam's device walk: for tests.
struct CoverageEntry {
  std::uint32_t pixel, prim;
  double area;  // square pixels, in (0, 1]
};
std::vector<CoverageEntry> beam_coverage(const Device& device, const Scene& scene, const BeamSettings& settings);

}  // namespace rtcl::beam
