// `rtcl render --method beam`: beam tracing (Heckbert and Hanrahan 1984).
// The viewing beam's tiles (8x8 pixels) are clipped on the device
// (beam_clipper.hpp). A fragment on a mirror (kr > 0) starts a reflected
// beam over the fragment in the scene transformed by the mirror's M_r
// (mirror.hpp); a fragment on a transmissive polygon (kt > 0) starts a
// reflected beam and a refracted beam, the latter in the scene transformed
// by the lecture's linearised M_t (refraction.hpp) built from the
// fragment's central ray (the ray through the centroid of its
// cross-section): one alpha per beam, exact for that ray, approximate for
// the others. Each child beam is clipped to the far side of its interface;
// its candidates come from a BVH frustum cull and the exact overlap test
// (beam_cull.hpp). Each level of the beam tree is one device launch, up to
// max_depth levels below the viewing beam. Every fragment is rasterised with
// exact coverage (the area of fragment ∩ pixel square, in double on the
// host) and shaded once per (fragment, pixel) at the point of its plane seen
// through the centroid of that area (mapped back to the real world), with
// the local Phong terms of the ray tracer (kernels/render/shade.cl:
// emission, ambient, Lambert, Phong highlight) and point lights whose
// shadows are shadow rays through the structure `accel` on the device.
// Radiance: I = C_d I_d + C_s I_s + Σ C_r I_r + Σ C_t I_t over the beam
// tree, with the ray tracer's weights: C_r the product down the tree of
// kr + kt F, C_t of kt (1 - F), F the Fresnel reflectance of the beam's
// central ray (F = 1 under total internal reflection: no refracted beam),
// plus the background times each beam's uncovered area.
#pragma once

#include <cstdint>
#include <string>

#include "rtcl/beam/beam_clip_host.hpp"
#include "rtcl/device.hpp"
#include "rtcl/render/image.hpp"
#include "rtcl/scene/scene_description.hpp"

namespace rtcl::beam {

// How the candidates of the beams below the viewing beam are found before
// the exact overlap test: the BVH frustum cull (beam_cull.hpp), or every
// triangle of the scene (the reference the cull is measured against).
enum class CandidateCull { bvh, all };

struct BeamSettings {
  std::uint32_t width = 512, height = 512;
  DepthOrder order = DepthOrder::exact;
  std::uint32_t max_depth = 5;  // beam-tree levels below the viewing beam (the ray tracer's --depth)
  float min_weight = 1e-3f;     // a child beam whose weight's largest component is below this is not traced
  CandidateCull cull = CandidateCull::bvh;
  std::string accel = "bvh";  // structure of the shadow rays
};

struct BeamStats {
  std::size_t polygons = 0;       // screen polygons after near and screen clipping
  std::size_t tiles = 0;          // tile beams
  std::size_t reflected_beams = 0;  // reflected beams, all levels
  std::size_t refracted_beams = 0;  // refracted beams, all levels
  std::size_t total_internal_reflections = 0;  // fragments whose central ray is totally reflected
  std::uint32_t levels = 0;         // beam-tree levels traced (1: the viewing beam only)
  std::size_t candidates = 0;     // (tile, polygon) pairs walked
  std::size_t fragments = 0;      // convex fragment pieces from the device
  std::size_t pixel_pieces = 0;   // (fragment, pixel) pairs shaded
  std::size_t shadow_rays = 0;
  double clip_ms = 0.0;           // device time of the clipping kernels (0 without profiling)
  double cull_ms = 0.0;           // host time of the candidates of the beams below the viewing beam
  double render_ms = 0.0;         // wall clock of the whole render
};

// Throws Error naming scene.source when the scene has spheres (beam tracing
// takes polygons only), an area light (point lights only), a glossy
// material (no glossy beams) or a moving object (a static scene).
void check_beam_scene(const SceneDescription& scene);

Image render_beam(const Device& device, const SceneDescription& scene, const BeamSettings& settings, BeamStats* stats = nullptr);

// Per pixel (row-major), the coverage of every visible triangle id by the
// fragments of the viewing beam's device walk: for tests.
struct CoverageEntry {
  std::uint32_t pixel, prim;
  double area;  // square pixels, in (0, 1]
};
std::vector<CoverageEntry> beam_coverage(const Device& device, const SceneDescription& scene, const BeamSettings& settings);

}  // namespace rtcl::beam
