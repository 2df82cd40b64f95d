/* The kd-tree packet traversal's (accel/kdtree_packet.cl) stack bound,
 * early-exit margin and empty-leaf test. See accel/kdtree.cl for the
 * single-ray traversal's contract. */
#ifndef RTCL_SHARED_KDTREE_H
#define RTCL_SHARED_KDTREE_H

#ifndef RTCL_KD_STACK
#error "RTCL_KD_STACK (the deepest tree) must be defined"
#endif

/* A subtree whose interval starts at t_min is skipped once the closest hit
 * t_best <= t_min - |t_min| * KD_EXIT_MARGIN (relative: covers the rounding
 * of the plane's dist and of the hit's t). */
#define KD_EXIT_MARGIN (4.0f * RTCL_SLAB_WIDEN)

/* A leaf with no references (the SAH's cut-off empty space). */
#define KD_EMPTY(node) (((node).flags & 3u) == RTCL_KD_LEAF && (node).data == 0u)

#endif
