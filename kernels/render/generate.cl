/* Camera rays of the wavefront renderer: one per pixel of a batch, in
 * screen-tile order (rtcl_tile_order_pixel), so that consecutive work-items
 * and packets of 8 trace coherent rays; or one per pixel of a list (the
 * selective and wavelet-guided renderers, src/rtcl/render/selective.hpp).
 *
 * Specialised by -D: RTCL_HAS_LENS (a thin-lens camera, aperture > 0). */
#include "shared/layouts.h"
#include "shared/render_layouts.h"
#include "shared/sampling.h"

inline float3 cam3(const float* a) { return (float3)(a[0], a[1], a[2]); }

/* The camera ray of sample `sample` of `spp` of pixel (x, y) of the image:
 * the sub-pixel position is the sampler's point in dimension RTCL_DIM_PIXEL
 * warped by the filter (shared/sampling.h); with a lens, the origin is the
 * sampler's point in RTCL_DIM_LENS on the aperture disc (concentric map) and
 * the ray passes through the pinhole ray's point at the focus distance.
 * Samples are keyed by the pixel's index in the whole image, so a pixel's
 * rays do not depend on which other pixels are traced. Unit direction;
 * tmin = 0, tmax = inf. */
inline Ray camera_ray(const DeviceCamera* c, uint x, uint y, uint sample, uint spp) {
  uint pixel = y * c->width + x;
  float su, sv, dx, dy;
  rtcl_sample_2d(c->sampler, c->seed, pixel, RTCL_DIM_PIXEL, sample, spp, &su, &sv);
  rtcl_filter_offset(c->filter, su, sv, &dx, &dy);
  float fx = (float)x + 0.5f + dx;
  float fy = (float)y + 0.5f + dy;
  float3 o = cam3(c->origin);
  float3 d = cam3(c->corner) + fx * cam3(c->du) + fy * cam3(c->dv);
#ifdef RTCL_HAS_LENS
  float lu, lv, a, b;
  rtcl_sample_2d(c->sampler, c->seed, pixel, RTCL_DIM_LENS, sample, spp, &lu, &lv);
  rtcl_concentric_disc(lu, lv, &a, &b);
  float3 lens = a * cam3(c->lens_u) + b * cam3(c->lens_v);
  d = c->focus_distance * d - lens; /* (origin + focus * d) - (origin + lens) */
  o += lens;
#endif
  d = normalize(d);
  Ray r;
  r.ox = o.x;
  r.oy = o.y;
  r.oz = o.z;
  r.dx = d.x;
  r.dy = d.y;
  r.dz = d.z;
  r.tmin = 0.0f;
  r.tmax = INFINITY;
  return r;
}

inline PathState camera_path(uint pixel) {
  PathState p;
  p.pixel = pixel;
  p.depth = 0;
  p.wr = p.wg = p.wb = 1.0f;
  return p;
}

/* Rays first .. first+count-1 of the tile order of the region x0 .. x0+rw-1,
 * y0 .. y0+rh-1 of the image (the whole image: 0, 0, width, height), for
 * sample `sample` of `spp` (camera_ray). Paths start at depth 0 with weight
 * 1; their pixel is the index inside the region, row-major. */
kernel void generate_camera_rays(global Ray* rays, global PathState* paths, global const DeviceCamera* camera,
                                 uint first, uint count, uint sample, uint spp, uint x0, uint y0, uint rw,
                                 uint rh) {
  uint i = get_global_id(0);
  if (i >= count) return;
  DeviceCamera c = *camera;
  uint at = rtcl_tile_order_pixel(first + i, rw, rh);
  rays[i] = camera_ray(&c, x0 + at % rw, y0 + at / rw, sample, spp);
  paths[i] = camera_path(at);
}

/* Rays of slots first .. first+count-1 of a pixel list: slot k is sample
 * k % spp of the image pixel pixels[k / spp] (y * width + x, each listed
 * once), so all samples of all listed pixels go in one launch (camera_ray);
 * their paths carry the slot (the shade kernel built with RTCL_PIXEL_SLOTS
 * reads the pixel and sample back from it). */
kernel void generate_camera_rays_at(global Ray* rays, global PathState* paths, global const DeviceCamera* camera,
                                    global const uint* pixels, uint first, uint count, uint spp) {
  uint i = get_global_id(0);
  if (i >= count) return;
  DeviceCamera c = *camera;
  uint slot = first + i;
  uint pixel = pixels[slot / spp];
  rays[i] = camera_ray(&c, pixel % c.width, pixel / c.width, slot % spp, spp);
  paths[i] = camera_path(slot);
}
