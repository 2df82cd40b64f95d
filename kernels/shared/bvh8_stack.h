/* The ordered push of a BVH8 node's children (kernels/accel/bvh.cl,
 * bvh_motion.cl, bvh_packet.cl, kdtree.cl, instances.cl): the children
 * whose lanes `hit` holds go onto the stack (stack_t, stack_ref, top sp),
 * kept sorted by decreasing entry distance t_entry within [sp at the node,
 * sp), so the nearest child pops first; an any-hit query skips the sorting
 * and leaves stack_t unwritten: its first hit ends the traversal, so its
 * pops test no entry distance. `node` is the Bvh8Node whose child[k] is
 * pushed for lane k. OpenCL C only. */
#ifndef RTCL_SHARED_BVH8_STACK_H
#define RTCL_SHARED_BVH8_STACK_H

/* What is pushed for lane k: the child reference, unless the kernel says
 * otherwise (the packet kernel's frustum traversal pushes child slots). */
#ifndef RTCL_BVH8_ENTRY
#define RTCL_BVH8_ENTRY(k) node->child[k]
#endif

/* Pushes entry E with entry distance T above the entries of distance < T
 * pushed since `base` (closest hit), or on top (any hit). */
#define RTCL_BVH8_PUSH_SORTED(T, E)                             \
  {                                                             \
    int j = sp++;                                               \
    while (!RTCL_ANY_HIT && j > base && stack_t[j - 1] < (T)) { \
      stack_t[j] = stack_t[j - 1];                              \
      stack_ref[j] = stack_ref[j - 1];                          \
      --j;                                                      \
    }                                                           \
    if (!RTCL_ANY_HIT) stack_t[j] = (T);                        \
    stack_ref[j] = (E);                                         \
  }

#define RTCL_BVH8_PUSH_LANE(k)                          \
  if (hit.s##k) {                                       \
    RTCL_BVH8_PUSH_SORTED(t_entry.s##k, RTCL_BVH8_ENTRY(k)) \
  }

/* Needs in scope: int8 hit, float8 t_entry, node, stack_t, stack_ref, sp. */
#define RTCL_BVH8_PUSH_CHILDREN                                                             \
  {                                                                                         \
    int base = sp;                                                                          \
    RTCL_BVH8_PUSH_LANE(0) RTCL_BVH8_PUSH_LANE(1) RTCL_BVH8_PUSH_LANE(2) RTCL_BVH8_PUSH_LANE(3) \
    RTCL_BVH8_PUSH_LANE(4) RTCL_BVH8_PUSH_LANE(5) RTCL_BVH8_PUSH_LANE(6) RTCL_BVH8_PUSH_LANE(7) \
  }

/* A hit lane of RTCL_BVH8_PUSH_CHILDREN_BUT_NEAREST, its entry distance
 * T and entry E, lanes taken in increasing order: the entry that would be
 * on top of the stack so far stays in (near_t, near_entry), out of the
 * stack. A lane not farther than it takes its place (ties: the later lane
 * is on top, as RTCL_BVH8_PUSH_SORTED leaves it); any hit: the later
 * lane. */
#define RTCL_BVH8_NEAR_ENTRY(T, E)              \
  {                                             \
    float t = (T);                              \
    int entry = (E);                            \
    if (!have) {                                \
      have = 1;                                 \
      near_t = t;                               \
      near_entry = entry;                       \
    } else if (RTCL_ANY_HIT || t <= near_t) {   \
      RTCL_BVH8_PUSH_SORTED(near_t, near_entry) \
      near_t = t;                               \
      near_entry = entry;                       \
    } else {                                    \
      RTCL_BVH8_PUSH_SORTED(t, entry)           \
    }                                           \
  }

/* Lane k of RTCL_BVH8_PUSH_CHILDREN_BUT_NEAREST. */
#define RTCL_BVH8_NEAR_LANE(k) \
  if (hit.s##k) RTCL_BVH8_NEAR_ENTRY(t_entry.s##k, RTCL_BVH8_ENTRY(k))

/* RTCL_BVH8_PUSH_CHILDREN followed by the pop of its top, without the
 * round trip through the stack: declares int near_entry, the entry on top,
 * and pushes the others in the same order. Needs some lane of `hit` set.
 * The pop's distance test is not made for near_entry: it fails only where
 * the widened entry distance lies above the current hit by less than the
 * slab widening, and the child then visited holds nothing nearer (its
 * tests use the same hit). The next node's address then comes from the node's
 * child load in registers, not from a store and a reload. */
#define RTCL_BVH8_PUSH_CHILDREN_BUT_NEAREST                                                   \
  int near_entry = 0;                                                                         \
  {                                                                                           \
    int base = sp, have = 0;                                                                  \
    float near_t = 0.0f;                                                                      \
    RTCL_BVH8_NEAR_LANE(0) RTCL_BVH8_NEAR_LANE(1) RTCL_BVH8_NEAR_LANE(2) RTCL_BVH8_NEAR_LANE(3) \
    RTCL_BVH8_NEAR_LANE(4) RTCL_BVH8_NEAR_LANE(5) RTCL_BVH8_NEAR_LANE(6) RTCL_BVH8_NEAR_LANE(7) \
  }

/* RTCL_BVH8_PUSH_CHILDREN_BUT_NEAREST over the hit lanes' bits
 * (rtcl_lane_bits8, shared/ray.h): the same pushes in the same order,
 * without a test of each lane; for nodes whose lanes are mostly empty or
 * missed (the instances' top level, kernels/accel/instances.cl). Needs
 * some lane of `hit` set, as that macro. */
#define RTCL_BVH8_PUSH_HIT_LANES_BUT_NEAREST                                   \
  int near_entry = 0;                                                         \
  {                                                                           \
    int base = sp, have = 0;                                                  \
    float near_t = 0.0f;                                                      \
    uint bits = (uint)rtcl_lane_bits8(hit);                                   \
    float lane_t[8];                                                          \
    vstore8(t_entry, 0, lane_t);                                              \
    do {                                                                      \
      int k = 31 - (int)clz(bits & (0u - bits)); /* the lowest set lane */    \
      bits &= bits - 1u;                                                      \
      RTCL_BVH8_NEAR_ENTRY(lane_t[k], RTCL_BVH8_ENTRY(k))                     \
    } while (bits);                                                           \
  }

#endif
