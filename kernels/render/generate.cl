/* Camera rays of the wavefront renderer: one per pixel of a batch, in
 * screen-tile order (rtcl_tile_order_pixel), so that consecutive work-items
 * and packets of 8 trace coherent rays. */
#include "shared/layouts.h"
#include "shared/render_layouts.h"

/* Rays first .. first+count-1 of the tile order, for sample `sample` of `spp`
 * (rtcl_sample_position). Directions are unit length; tmin = 0, tmax = inf.
 * Paths start at depth 0 with weight 1. */
kernel void generate_camera_rays(global Ray* rays, global PathState* paths, global const DeviceCamera* camera,
                                 uint first, uint count, uint sample, uint spp) {
  uint i = get_global_id(0);
  if (i >= count) return;
  DeviceCamera c = *camera;
  uint pixel = rtcl_tile_order_pixel(first + i, c.width, c.height);
  float jx, jy;
  rtcl_sample_position(pixel, sample, spp, &jx, &jy);
  float fx = (float)(pixel % c.width) + jx;
  float fy = (float)(pixel / c.width) + jy;
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
  p.pixel = pixel;
  p.depth = 0;
  p.wr = p.wg = p.wb = 1.0f;
  paths[i] = p;
}
