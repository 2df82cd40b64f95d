/* Two-level scenes, one ray per work-item (src/rtcl/scene/two_level.hpp):
 * a top-level 8-wide BVH over the instances' world boxes, walked with the
 * world ray; at an instance the ray goes into its mesh's space and walks
 * that mesh's bottom level with the traversal of the BVH structure
 * (shared/bvh8_traverse.h). Layouts: BottomLevel, InstanceRecord and
 * InstanceMotion (shared/layouts.h).
 *
 * Object space: o' = A^-1 (o - T), d' = A^-1 d for the instance's
 * object-to-world transform x -> A x + T; the direction is not
 * renormalised, so a point o' + t d' of the mesh is the world point
 * o + t d: t, the closest hit's order and tmin / tmax are the world ray's,
 * and the barycentrics u, v of the mesh's triangle are those of its world
 * image (an affine map keeps them). The watertight test accepts either
 * winding, so a mirroring transform (det A < 0) needs nothing more. The
 * whole mesh is tested with one object ray, so a closed mesh stays closed
 * for it: no ray leaks between its triangles at the robust level.
 *
 * Moving instances (RTCL_INSTANCES_MOVING): ray i's time tau is
 * times[i * time_stride + time_offset] clamped to [0, 1] (NaN: 0); the
 * transform at tau is the element-wise blend of InstanceMotion's two, and
 * A^-1 its inverse computed here (cofactors over the determinant, float).
 * Their top-level boxes hold the mesh over the whole of [0, 1].
 *
 * RTCL_TOP_ONE_INSTANCE (a scene of one instance): the ray goes to
 * instance 0 without the top level's box test, which only culls what the
 * bottom level's root culls too.
 *
 * Stack: one for both levels, of RTCL_TOP_STACK_SIZE (the top tree's
 * bound as the host computes it for the BVH) plus RTCL_STACK_SIZE (the
 * largest bound of the bottom levels) entries: an identity instance's
 * bottom level is walked inline above the top level's entries
 * (bvh_walk), without a call and a stack of its own; a transformed one
 * calls bvh_traverse, which keeps its own. */
#define RTCL_INLINE_TRIANGLE_LANES
#define RTCL_INLINE_TRIANGLE_BLOCK
#define RTCL_INLINE_RAY_SETUP
#include "shared/bvh8_traverse.h"

#ifndef RTCL_TOP_STACK_SIZE
#define RTCL_TOP_STACK_SIZE 64
#endif

/* The world ray s as the ray of instance `in` at time tau (object space;
 * tmin and tmax unchanged), for an instance whose linear part is not the
 * identity or that moves. Scalars throughout: PoCL keeps them in
 * registers, where small arrays went through memory. */
inline Ray instance_object_ray(const TraceRay* s, global const InstanceRecord* in,
                               global const InstanceMotion* motions, float tau) {
  Ray r;
  r.tmin = s->tmin;
  r.tmax = s->tmax;
  float a0, a1, a2, a3, a4, a5, a6, a7, a8, tx, ty, tz;
#ifdef RTCL_INSTANCES_MOVING
  if (in->flags & RTCL_INSTANCE_MOVING) {
    global const InstanceMotion* m = motions + in->motion;
#define RTCL_BLEND(k) (m->open[k] + tau * (m->close[k] - m->open[k]))
    /* rows of A: elements 0..2, 4..6, 8..10; T: 3, 7, 11 */
    float b0 = RTCL_BLEND(0), b1 = RTCL_BLEND(1), b2 = RTCL_BLEND(2);
    float b4 = RTCL_BLEND(4), b5 = RTCL_BLEND(5), b6 = RTCL_BLEND(6);
    float b8 = RTCL_BLEND(8), b9 = RTCL_BLEND(9), b10 = RTCL_BLEND(10);
    tx = RTCL_BLEND(3);
    ty = RTCL_BLEND(7);
    tz = RTCL_BLEND(11);
#undef RTCL_BLEND
    /* A^-1 = adj(A) / det A, the adjugate's rows from the cofactors */
    float c00 = b5 * b10 - b6 * b9, c01 = b2 * b9 - b1 * b10, c02 = b1 * b6 - b2 * b5;
    float c10 = b6 * b8 - b4 * b10, c11 = b0 * b10 - b2 * b8, c12 = b2 * b4 - b0 * b6;
    float c20 = b4 * b9 - b5 * b8, c21 = b1 * b8 - b0 * b9, c22 = b0 * b5 - b1 * b4;
    float inv_det = 1.0f / (b0 * c00 + b1 * c10 + b2 * c20);
    a0 = c00 * inv_det; a1 = c01 * inv_det; a2 = c02 * inv_det;
    a3 = c10 * inv_det; a4 = c11 * inv_det; a5 = c12 * inv_det;
    a6 = c20 * inv_det; a7 = c21 * inv_det; a8 = c22 * inv_det;
  } else
#endif
  {
    tx = in->translation[0];
    ty = in->translation[1];
    tz = in->translation[2];
    global const float* t = in->to_object;
    a0 = t[0]; a1 = t[1]; a2 = t[2];
    a3 = t[3]; a4 = t[4]; a5 = t[5];
    a6 = t[6]; a7 = t[7]; a8 = t[8];
  }
  float px = s->ox - tx, py = s->oy - ty, pz = s->oz - tz;
  r.ox = a0 * px + a1 * py + a2 * pz;
  r.oy = a3 * px + a4 * py + a5 * pz;
  r.oz = a6 * px + a7 * py + a8 * pz;
  r.dx = a0 * s->dx + a1 * s->dy + a2 * s->dz;
  r.dy = a3 * s->dx + a4 * s->dy + a5 * s->dz;
  r.dz = a6 * s->dx + a7 * s->dy + a8 * s->dz;
  return r;
}

#define INSTANCES_PARAMS                                                                                    \
  global const Bvh8Node *top, global const InstanceRecord *instances, global const InstanceMotion *motions, \
      global const BottomLevel *bottoms, global const Bvh8Node *nodes, global const TriangleBlock *triangles, \
      global const SphereBlock *spheres
#define INSTANCES_ARGS top, instances, motions, bottoms, nodes, triangles, spheres

/* The walk of the bottom level (nodes, triangles, spheres) of
 * instance `in`, whose transform is not the identity, with its object ray
 * set up in s itself; s is restored after the walk (on PoCL a walk with a
 * copy of the ray record is markedly slower than with the kernel's own
 * record: docs/benchmarks.md). An instance that only translates
 * (RTCL_INSTANCE_LINEAR_IDENTITY) changes the origin alone (the
 * direction's setup stays the world ray's, bit for bit what
 * trace_ray_setup gives for it); any other has the whole setup
 * (trace_ray_setup) of its object ray. Out of line: its code beside the
 * identity instance's call cost that call some 4% (bench/scenes/
 * instances_bench.cpp). Returns bvh_traverse's answer. */
__attribute__((noinline)) int instance_walk_transformed(TraceRay* s, HitState* h,
                                                         global const InstanceRecord* in,
                                                         global const InstanceMotion* motions, float tau,
                                                         global const Bvh8Node* nodes,
                                                         global const TriangleBlock* triangles,
                                                         global const SphereBlock* spheres) {
  int leaf;
  if ((in->flags & (RTCL_INSTANCE_LINEAR_IDENTITY | RTCL_INSTANCE_MOVING)) == RTCL_INSTANCE_LINEAR_IDENTITY) {
    float ox = s->ox, oy = s->oy, oz = s->oz, okx = s->okx, oky = s->oky, okz = s->okz;
    global const float* t = in->translation;
    s->ox = ox - t[0];
    s->oy = oy - t[1];
    s->oz = oz - t[2];
    /* the permuted origin's components are the same differences */
    s->okx = okx - t[s->kx];
    s->oky = oky - t[s->ky];
    s->okz = okz - t[s->kz];
    leaf = bvh_traverse(s, h, nodes, triangles, spheres);
    s->ox = ox;
    s->oy = oy;
    s->oz = oz;
    s->okx = okx;
    s->oky = oky;
    s->okz = okz;
  } else {
    TraceRay world = *s;
    leaf = trace_ray_setup(instance_object_ray(&world, in, motions, tau), s)
               ? bvh_traverse(s, h, nodes, triangles, spheres)
               : -1;
    *s = world;
  }
  return leaf;
}

/* Instance k against the ray: its bottom level walked with the object
 * ray, for an identity instance (RTCL_INSTANCE_IDENTITY) the world ray
 * itself, as the flat structure walks it.
 * The stack's entries from sp up are free for the walk.
 * Records a nearer hit in h and k in *hit_instance; returns whether it
 * recorded one (any hit: whether the instance blocks the ray). Inlined:
 * as a call of its own the identity instance's walk ran about 4% more
 * instructions per ray (577 against 553, callgrind). */
inline __attribute__((always_inline)) int instance_visit(uint k, TraceRay* s, HitState* h, float tau,
                                                         uint* hit_instance, int* stack_ref, float* stack_t, int sp,
                                                         INSTANCES_PARAMS) {
  global const InstanceRecord* in = instances + k;
  BottomLevel b = bottoms[in->bottom];
  global const Bvh8Node* bottom_nodes = nodes + b.node_offset;
  global const TriangleBlock* bottom_triangles = triangles + b.triangle_offset;
  global const SphereBlock* bottom_spheres = spheres + b.sphere_offset;
  float t_before = h->t_best;
  int prim_before = h->prim;
#ifdef RTCL_PRECISION_EXACT
  double exact_before = h->t_exact;
#endif
  int leaf = (in->flags & RTCL_INSTANCE_IDENTITY)
                 ? bvh_walk(s, h, bottom_nodes, bottom_triangles, bottom_spheres, stack_ref, stack_t, sp)
                 : instance_walk_transformed(s, h, in, motions, tau, bottom_nodes, bottom_triangles, bottom_spheres);
  int found = h->t_best != t_before || h->prim != prim_before;
#ifdef RTCL_PRECISION_EXACT
  found = found || h->t_exact != exact_before;
#endif
  if (found) *hit_instance = k;
  return RTCL_ANY_HIT ? leaf >= 0 : found;
}

/* The top level's traversal (the order of kernels/accel/bvh.cl: nearest
 * child first, entries beyond the current hit skipped; any hit: the first
 * hit ends it). Returns the instance of the hit recorded in h (0 for a
 * miss). */
__attribute__((noinline)) uint instances_traverse(TraceRay* s, HitState* h, float tau, INSTANCES_PARAMS) {
  uint hit_instance = 0;
  int stack_ref[RTCL_TOP_STACK_SIZE + RTCL_STACK_SIZE];
  float stack_t[RTCL_TOP_STACK_SIZE + RTCL_STACK_SIZE];
  int sp = 0;
  int ref = 0;
#ifdef RTCL_TOP_ONE_INSTANCE
  ref = ~0; /* a top level of one instance: its bottom level's root decides alone */
#endif
  for (;;) {
    if (ref >= 0) {
      global const Bvh8Node* node = top + ref;
      float8 t_entry;
      int8 hit = intersect_boxes8(node, s, h->t_best, &t_entry);
      if (rtcl_any8(hit)) {
        /* the hit lanes' bits: a top node's lanes are often mostly empty
         * or missed, and the top level then runs 6-9% fewer instructions
         * than with RTCL_BVH8_PUSH_CHILDREN_BUT_NEAREST's test of every lane
         * (docs/benchmarks.md, "Instances"); the bottom levels keep that */
        RTCL_BVH8_PUSH_HIT_LANES_BUT_NEAREST
        ref = near_entry;
        continue;
      }
    } else if (instance_visit((uint)~ref, s, h, tau, &hit_instance, stack_ref, stack_t, sp, INSTANCES_ARGS) &&
               RTCL_ANY_HIT) {
      return hit_instance;
    }
    do {
      if (sp == 0) return hit_instance;
      --sp;
    } while (!RTCL_ANY_HIT && stack_t[sp] > h->t_best);
    ref = stack_ref[sp];
  }
}

/* hits[i] as every trace kernel writes it (prim: the primitive within its
 * mesh); with write_ids, instance_ids[i] the hit instance's user_id, or
 * 0xffffffff for a miss. */
kernel void RTCL_TRACE_KERNEL_NAME(instances)(global const Ray* rays, global Hit* hits, uint ray_count,
                                              global uint* instance_ids, uint write_ids, global const float* times,
                                              uint time_stride, uint time_offset, INSTANCES_PARAMS) {
  uint i = get_global_id(0);
  if (i >= ray_count) return;
  float tau = 0.0f;
#ifdef RTCL_INSTANCES_MOVING
  tau = times[(ulong)i * time_stride + time_offset];
  /* a bit test for NaN: -cl-fast-relaxed-math (the fast level) lets the
   * compiler assume a comparison with NaN never happens */
  tau = rtcl_is_nan(tau) ? 0.0f : fmin(fmax(tau, 0.0f), 1.0f);
#endif
  TraceRay s;
  HitState h;
  uint hit_instance = begin_trace(rays, i, &s, &h) ? instances_traverse(&s, &h, tau, INSTANCES_ARGS) : 0;
  end_trace(hits, i, &h);
  if (write_ids) instance_ids[i] = h.prim >= 0 ? instances[hit_instance].user_id : 0xffffffffu;
}

/* A scene of one instance traced by its mesh's own structure: ids[i] is
 * user_id where hits[i] is a hit, else 0xffffffff. */
kernel void instance_ids_of_hits(global const Hit* hits, global uint* ids, uint count, uint user_id) {
  uint i = get_global_id(0);
  if (i < count) ids[i] = hits[i].prim >= 0 ? user_id : 0xffffffffu;
}
