/* The ordered push of a BVH8 node's children (kernels/accel/bvh.cl,
 * bvh_motion.cl): the children whose lanes `hit` holds go onto the stack
 * (stack_t, stack_ref, top sp), kept sorted by decreasing entry distance
 * t_entry within [sp at the node, sp), so the nearest child pops first; an
 * any-hit query skips the sorting and leaves stack_t unwritten: its first
 * hit ends the traversal, so its pops test no entry distance (measured:
 * 0.92-1.13x the shadow rays' kernel time, medians of two runs, above
 * 1.03x in 6 of 8, README "Kernel levers on the single-ray BVH"). `node`
 * is the Bvh8Node whose child[k] is pushed for lane k. OpenCL C only. */
#ifndef RTCL_SHARED_BVH8_STACK_H
#define RTCL_SHARED_BVH8_STACK_H

/* What is pushed for lane k: the child reference, unless the kernel says
 * otherwise (the packet kernel's frustum traversal pushes child slots). */
#ifndef RTCL_BVH8_ENTRY
#define RTCL_BVH8_ENTRY(k) node->child[k]
#endif

#define RTCL_BVH8_PUSH_LANE(k)                                \
  if (hit.s##k) {                                             \
    float t = t_entry.s##k;                                   \
    int j = sp++;                                             \
    while (!RTCL_ANY_HIT && j > base && stack_t[j - 1] < t) { \
      stack_t[j] = stack_t[j - 1];                            \
      stack_ref[j] = stack_ref[j - 1];                        \
      --j;                                                    \
    }                                                         \
    if (!RTCL_ANY_HIT) stack_t[j] = t;                        \
    stack_ref[j] = RTCL_BVH8_ENTRY(k);                        \
  }

/* Needs in scope: int8 hit, float8 t_entry, node, stack_t, stack_ref, sp. */
#define RTCL_BVH8_PUSH_CHILDREN                                                             \
  {                                                                                         \
    int base = sp;                                                                          \
    RTCL_BVH8_PUSH_LANE(0) RTCL_BVH8_PUSH_LANE(1) RTCL_BVH8_PUSH_LANE(2) RTCL_BVH8_PUSH_LANE(3) \
    RTCL_BVH8_PUSH_LANE(4) RTCL_BVH8_PUSH_LANE(5) RTCL_BVH8_PUSH_LANE(6) RTCL_BVH8_PUSH_LANE(7) \
  }

#endif
