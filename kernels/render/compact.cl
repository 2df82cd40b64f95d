/* Stream compaction of flagged slots into a dense queue, order preserving:
 * count flags per chunk, scan the chunk counts, scatter. Each work-item owns
 * a contiguous chunk of RTCL_SCAN_CHUNK slots (no barriers, no local memory:
 * on a CPU device a work-item is a sequential loop anyway), so the result is
 * deterministic and slot order is kept: the children of one pixel's paths
 * stay contiguous, which accumulate_radiance relies on. */
#include "shared/layouts.h"
#include "shared/render_layouts.h"

/* counts[2c] = flagged slots of chunk c, counts[2c+1] = those flagged
 * RTCL_SLOT_REFRACTION. One work-item per chunk. */
kernel void count_flags(global const uint* flags, uint slot_count, global uint* counts) {
  uint c = get_global_id(0);
  uint begin = c * RTCL_SCAN_CHUNK;
  if (begin >= slot_count) return;
  uint end = min(begin + RTCL_SCAN_CHUNK, slot_count);
  uint n = 0, refracted = 0;
  for (uint s = begin; s < end; ++s) {
    uint f = flags[s];
    n += f != RTCL_SLOT_EMPTY;
    refracted += f == RTCL_SLOT_REFRACTION;
  }
  counts[2 * c] = n;
  counts[2 * c + 1] = refracted;
}

/* Exclusive prefix sum of counts[2c] in place (one work-item); writes the
 * flagged total to totals[at] and the refraction total to totals[at + 1]. */
kernel void scan_counts(global uint* counts, uint chunk_count, global uint* totals, uint at) {
  if (get_global_id(0) != 0) return;
  uint sum = 0, refracted = 0;
  for (uint c = 0; c < chunk_count; ++c) {
    uint n = counts[2 * c];
    counts[2 * c] = sum;
    sum += n;
    refracted += counts[2 * c + 1];
  }
  totals[at] = sum;
  totals[at + 1] = refracted;
}

/* Shadow rays: dense queue and, per flagged slot, its index in the queue. */
kernel void compact_shadow_rays(global const uint* flags, uint slot_count, global const uint* counts,
                                global const Ray* slot_rays, global Ray* queue_rays, global uint* slot_index) {
  uint c = get_global_id(0);
  uint begin = c * RTCL_SCAN_CHUNK;
  if (begin >= slot_count) return;
  uint end = min(begin + RTCL_SCAN_CHUNK, slot_count);
  uint out = counts[2 * c];
  for (uint s = begin; s < end; ++s) {
    if (flags[s] == RTCL_SLOT_EMPTY) continue;
    queue_rays[out] = slot_rays[s];
    slot_index[s] = out;
    ++out;
  }
}

/* Spawned reflection and refraction rays with their path states. */
kernel void compact_spawned_rays(global const uint* flags, uint slot_count, global const uint* counts,
                                 global const Ray* slot_rays, global const PathState* slot_paths,
                                 global Ray* queue_rays, global PathState* queue_paths) {
  uint c = get_global_id(0);
  uint begin = c * RTCL_SCAN_CHUNK;
  if (begin >= slot_count) return;
  uint end = min(begin + RTCL_SCAN_CHUNK, slot_count);
  uint out = counts[2 * c];
  for (uint s = begin; s < end; ++s) {
    if (flags[s] == RTCL_SLOT_EMPTY) continue;
    queue_rays[out] = slot_rays[s];
    queue_paths[out] = slot_paths[s];
    ++out;
  }
}
