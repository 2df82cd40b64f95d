/* Ray times of a moving scene's wavefront, read by accel/bvh_motion.cl:
 * every ray of a path (camera ray, reflections, refractions, shadow rays)
 * has its pixel sample's time (shared/sampling.h, rtcl_sample_time), the
 * value the shade kernel recomputes for the path's hit points. */
#include "shared/layouts.h"
#include "shared/render_layouts.h"
#include "shared/sampling.h"

/* times[i] for queued ray i (< count) of pixel sample `sample` of `spp`;
 * paths index pixels inside the region x0 .. x0+rw-1 (rows from y0) of an
 * image `width` pixels wide, samples are keyed by the whole image's pixel.
 * listed != 0: the paths index sample slots of a pixel list instead (slot
 * p: sample p % spp of image pixel pixel_list[p / spp], as the shade
 * kernel's RTCL_PIXEL_SLOTS) and `sample` is unused. */
kernel void queue_ray_times(global const PathState* paths, uint count, uint sample, uint spp, uint sampler,
                            uint seed, uint x0, uint y0, uint rw, uint width, global float* times, uint listed,
                            global const uint* pixel_list) {
  uint i = get_global_id(0);
  if (i >= count) return;
  uint at = paths[i].pixel;
  uint image_pixel = listed ? pixel_list[at / spp] : (y0 + at / rw) * width + x0 + at % rw;
  times[i] = rtcl_sample_time(sampler, seed, image_pixel, listed ? at % spp : sample, spp);
}

/* The shadow queue's times: slot i * shadow_slots + k of queued ray i, when
 * flagged, became shadow ray slot_index[slot] and takes ray i's time. */
kernel void shadow_ray_times(global const float* times, uint count, uint shadow_slots, global const uint* flags,
                             global const uint* slot_index, global float* shadow_times) {
  uint i = get_global_id(0);
  if (i >= count) return;
  for (uint k = 0; k < shadow_slots; ++k) {
    uint slot = i * shadow_slots + k;
    if (flags[slot] != RTCL_SLOT_EMPTY) shadow_times[slot_index[slot]] = times[i];
  }
}
