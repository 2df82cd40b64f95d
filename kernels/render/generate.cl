/* Camera rays of the wavefront renderer: one per pixel of a batch, in
 * screen-tile order (rtcl_tile_order_pixel), so that consecutive work-items
 * and packets of 8 trace coherent rays. */
#include "shared/layouts.h"
#include "shared/render_layouts.h"

/* Rays first .. first+count-1 of the tile order of the region x0 .. x0+rw-1,
 * y0 .. y0+rh-1 of the image (the whole image: 0, 0, width, height), for
 * sample `sample` of `spp` (rtcl_sample_position, keyed by the pixel's index
 * in the whole image, so a pixel's rays do not depend on the region).
 * Directions are unit length; tmin = 0, tmax = inf. Paths start at depth 0
 * with weight 1; their pixel is the index inside the region, row-major. */
kernel void generate_camera_rays(global Ray* rays, global PathState* paths, global const DeviceCamera* camera,
                                 uint first, uint count, uint sample, uint spp, uint x0, uint y0, uint rw,
                                 uint rh) {
  uint i = get_global_id(0);
  if (i >= count) return;
  DeviceCamera c = *camera;
  uint at = rtcl_tile_order_pixel(first + i, rw, rh);
  uint x = x0 + at % rw, y = y0 + at / rw;
  uint pixel = y * c.width + x;
  float jx, jy;
  rtcl_sample_position(pixel, sample, spp, &jx, &jy);
  float fx = (float)x + jx;
  float fy = (float)y + jy;
  float3 d = (float3)(c.corner[0], c.corner[1], c.corner[2]) + fx * (float3)(c.du[0], c.du[1], c.du[2]) +
             fy * (float3)(c.dv[0], c.dv[1], c.dv[2]);
  d = normalize(d);
  Ray r;
  r.ox = c.origin[0];
  r.oy = c.origin[1];
  r.oz = c.origin[2];
  r.dx = d.x;
  r.dy = d.y;
  r.dz = d.z;
  r.tmin = 0.0f;
  r.tmax = INFINITY;
  rays[i] = r;
  PathState p;
  p.pixel = at;
  p.depth = 0;
  p.wr = p.wg = p.wb = 1.0f;
  paths[i] = p;
}
