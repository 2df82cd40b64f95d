/* 8-wide BVH traversal, one packet of 8 consecutive rays per work-item: the
 * same BVH8 as accel/bvh.cl (same build, same node and block layout), but the
 * float8 lanes hold the eight rays instead of a node's eight children
 * (packet traversal, Wald, Slusallek, Benthin, Wagner 2001, "Interactive
 * rendering with coherent ray tracing"). Per node, each child box is tested
 * against the packet's rays at once; per leaf, each primitive is tested
 * against them at once. The packet shares one stack; each entry carries the
 * per-ray entry distances of its box, NaN for the rays that missed it, so
 * that a popped entry is active exactly for the rays that entered its box
 * before their current closest hit.
 *
 * Contract: rays 8p .. 8p+7 (those below ray_count) form packet p; any rays
 * work (coherent ones, e.g. screen tiles or Morton order, are faster). Every
 * ray gets exactly the arithmetic of accel/bvh.cl (shared/box.h,
 * shared/triangle.h, shared/sphere.h) at every precision level: the same
 * slab distances and the same triangle tests, lane by lane, so closest-hit
 * t is bit-identical to the single-ray kernel (at the robust and fast levels
 * the primitive may differ between two at exactly the same t; at the exact
 * level the smaller id wins there too). Any hit reports some hit.
 *
 * Stack bound: as in accel/bvh.cl (a node pushes at most its children and
 * pops one), so the host's RTCL_STACK_SIZE is valid here too. */
#include "shared/packet.h"

#ifndef RTCL_STACK_SIZE
#define RTCL_STACK_SIZE 64
#endif

/* Child c's box against the packet over [tmin, t_best]: rtcl_slabs8, the
 * arithmetic of intersect_boxes8, per lane (entry plane chosen by the
 * lane's direction sign).
 * Returns the entry distances, NaN where the ray misses the box. */
inline float8 packet_box(global const Bvh8Node* node, int c, const TracePacket* p, float8 t_best, int8 mask) {
  float lx = node->bounds[0][c], ly = node->bounds[1][c], lz = node->bounds[2][c];
  float ux = node->bounds[3][c], uy = node->bounds[4][c], uz = node->bounds[5][c];
  float8 tn, tf;
  rtcl_slabs8(select((float8)(ux), (float8)(lx), p->pos_x), select((float8)(uy), (float8)(ly), p->pos_y),
              select((float8)(uz), (float8)(lz), p->pos_z), select((float8)(lx), (float8)(ux), p->pos_x),
              select((float8)(ly), (float8)(uy), p->pos_y), select((float8)(lz), (float8)(uz), p->pos_z), p->ox,
              p->oy, p->oz, p->ix, p->iy, p->iz, p->tmin, t_best, &tn, &tf);
  return select((float8)(NAN), tn, mask & (tn <= tf));
}

/* Triangle k of a block against the packet (packet_triangle_at). */
inline int8 packet_triangle(global const TriangleBlock* block, int k, const TracePacket* p, PacketHits* h,
                            int8 mask) {
  return packet_triangle_at(&block->v[0][0][k], RTCL_BLOCK_WIDTH, block->prim[k], p, h, mask);
}

/* Traverses the packet. Any hit: a ray leaves the packet at its first hit;
 * the traversal ends when every ray has. */
__attribute__((noinline)) void bvh_packet_traverse(const TracePacket* p, PacketHits* h, global const Bvh8Node* nodes,
                                                   global const TriangleBlock* triangles,
                                                   global const SphereBlock* spheres) {
  float8 stack_t[RTCL_STACK_SIZE]; /* entry distances of stack_ref's box, NaN: ray not in it */
  int stack_ref[RTCL_STACK_SIZE];
  float stack_key[RTCL_STACK_SIZE]; /* nearest entry distance over the packet: visiting order */
  int sp = 0;
  int ref = 0;
  int8 alive = p->active; /* any hit: rays still looking */
  int8 mask = alive;
  for (;;) {
    if (ref >= 0) {
      global const Bvh8Node* node = nodes + ref;
      int base = sp;
      for (int c = 0; c < 8; ++c) {
        int child = node->child[c];
        if (child == RTCL_CHILD_EMPTY) continue;
        float8 tn = packet_box(node, c, p, h->t_best, mask);
        int8 in = tn == tn;
        if (!rtcl_any8(in)) continue;
        float key = rtcl_min8(select((float8)(INFINITY), tn, in));
        /* insertion into [base, sp) kept sorted by decreasing key */
        int j = sp++;
        while (!RTCL_ANY_HIT && j > base && stack_key[j - 1] < key) {
          stack_key[j] = stack_key[j - 1];
          stack_t[j] = stack_t[j - 1];
          stack_ref[j] = stack_ref[j - 1];
          --j;
        }
        stack_key[j] = key;
        stack_t[j] = tn;
        stack_ref[j] = child;
      }
    } else {
      int leaf = ~ref;
#ifdef RTCL_HAS_SPHERES
      if (leaf & 1) {
        global const SphereBlock* block = spheres + (leaf >> 1);
        for (int k = 0; k < RTCL_BLOCK_WIDTH; ++k) {
          if (block->prim[k] < 0) continue;
          int8 hit = packet_sphere(block, k, p, h, mask);
          if (RTCL_ANY_HIT) {
            alive &= ~hit;
            mask &= ~hit;
          }
        }
      } else
#endif
      {
        global const TriangleBlock* block = triangles + (leaf >> 1);
        for (int k = 0; k < RTCL_BLOCK_WIDTH; ++k) {
          if (block->prim[k] < 0) continue;
          int8 hit = packet_triangle(block, k, p, h, mask);
          if (RTCL_ANY_HIT) {
            alive &= ~hit;
            mask &= ~hit;
          }
        }
      }
      if (RTCL_ANY_HIT && !rtcl_any8(alive)) return;
    }
    /* pop the next entry some ray still needs: entered before its best hit */
    for (;;) {
      if (sp == 0) return;
      --sp;
      mask = alive & (stack_t[sp] <= h->t_best);
      if (rtcl_any8(mask)) break;
    }
    ref = stack_ref[sp];
  }
}

#define BVH_PACKET_PARAMS global const Bvh8Node *nodes, global const TriangleBlock *triangles, global const SphereBlock *spheres
#define BVH_PACKET_ARGS nodes, triangles, spheres
RTCL_PACKET_KERNELS(bvh_packet, BVH_PACKET_PARAMS, BVH_PACKET_ARGS)
