/* Refit of the 8-wide BVH (src/rtcl/accel/refit.hpp): the tree keeps its
 * shape, the triangle blocks are filled again from new vertices and every
 * node's child boxes are recomputed bottom-up (Bvh8Node, TriangleBlock:
 * shared/layouts.h), in one launch.
 *
 * Lane vertices: lane_vertices[24 b + 8 k + lane] is the index of corner k
 * (0..2) of the triangle in lane `lane` of triangle block b, or
 * RTCL_REFIT_NO_LANE for an unused lane. refit_lane_vertices makes it from
 * the triangles' indices when they are new; then each refit reads the
 * corners' indices in block order, not through the triangles.
 *
 * refit_bottom_up, one work-item per block node (a node with at least one
 * triangle block among its lanes), then one per start node (a node none of
 * whose lanes is a triangle block or an inner node: only sphere blocks,
 * which keep their build's boxes): a block node's work-item fills its
 * blocks' lanes from the vertices and writes each block's box (that of its
 * corners) into the block's lane of the node. Each node counts the lanes
 * written into it (counters[n], atomically; a work-item that wrote all of
 * a node's lanes itself skips the count); the work-item whose count
 * completes arrivals[n] (the node's triangle-block and inner-node lanes)
 * goes on with that node: it reads the node's eight lanes, writes the
 * node's share of the SAH cost, writes the node's box into its own lane
 * of its parent, and so up, until the root. Every node is thus finished
 * once, after all of its children, by one work-item, in one launch; the
 * finishing work-item sets the counter back to 0 for the next refit. A
 * work-item per block node rather than per block: the count's atomic (a
 * full barrier on a CPU, waiting for the block's stores) is paid per node,
 * and a node's blocks are filled by one core. up[n] is node n's parent's
 * index times 8 plus its lane (the root's is RTCL_REFIT_ROOT).
 *
 * Memory: the lane writes come before a global fence and the counter's
 * atomic increment; the finishing work-item fences after its increment and
 * reads the node's lanes through a volatile pointer, so that a device
 * whose caches are not coherent between compute units reads them from
 * global memory. This is the classic bottom-up refit of GPU BVH builders;
 * OpenCL 1.2 promises no order between work-groups, so it relies on the
 * device's global fences and atomics ordering memory, as a CPU device's
 * coherent caches do and GPUs' fences do in practice.
 *
 * Boxes are the exact float minima and maxima of the corners (no
 * rounding), so every lane's box contains what lies below it. cost_parts[n]
 * is the sum over node n's used lanes of the lane box's area, times
 * node_cost for an inner child, times 1 for a block (refit.cpp sums
 * them). */
#include "shared/layouts.h"

#define RTCL_REFIT_NO_LANE 0xffffffffu
#define RTCL_REFIT_ROOT 0xffffffffu

kernel void refit_lane_vertices(global const TriangleBlock* blocks, uint lane_count, global const uint* indices,
                                global uint* lane_vertices) {
  const uint i = get_global_id(0);
  if (i >= lane_count) return;
  const uint b = i / RTCL_BLOCK_WIDTH, lane = i % RTCL_BLOCK_WIDTH;
  const int prim = blocks[b].prim[lane];
  global uint* out = lane_vertices + 3 * RTCL_BLOCK_WIDTH * b + lane;
  const uint3 t = prim < 0 ? (uint3)(RTCL_REFIT_NO_LANE) : vload3((size_t)prim, indices);
  out[0] = t.x;
  out[RTCL_BLOCK_WIDTH] = t.y;
  out[2 * RTCL_BLOCK_WIDTH] = t.z;
}

float box_area(float3 lo, float3 hi) {
  const float3 e = hi - lo;
  return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
}

/* Componentwise minimum and maximum of finite values (refit.cpp refuses
 * vertices that are not finite): plain compares, which a CPU compiler turns
 * into one instruction each, where fmin and fmax also order NaNs. */
float3 min3(float3 a, float3 b) { return select(b, a, a < b); }
float3 max3(float3 a, float3 b) { return select(b, a, a > b); }

/* Block b's lanes from the vertices; returns their box in *lo, *hi. */
void fill_block(global TriangleBlock* block, global const uint* corners, global const float* vertices, float3* lo,
                float3* hi) {
  float3 l = (float3)(INFINITY), h = (float3)(-INFINITY);
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
    const uint i0 = corners[lane];
    if (i0 == RTCL_REFIT_NO_LANE) continue;
    const uint i1 = corners[RTCL_BLOCK_WIDTH + lane], i2 = corners[2 * RTCL_BLOCK_WIDTH + lane];
    const float3 a = vload3(i0, vertices), b = vload3(i1, vertices), c = vload3(i2, vertices);
    block->v[0][0][lane] = a.x;
    block->v[0][1][lane] = a.y;
    block->v[0][2][lane] = a.z;
    block->v[1][0][lane] = b.x;
    block->v[1][1][lane] = b.y;
    block->v[1][2][lane] = b.z;
    block->v[2][0][lane] = c.x;
    block->v[2][1][lane] = c.y;
    block->v[2][2][lane] = c.z;
    l = min3(l, min3(a, min3(b, c)));
    h = max3(h, max3(a, max3(b, c)));
  }
  *lo = l;
  *hi = h;
}

/* Lane `up % 8` of node `up / 8` set to the box. */
void write_lane(global Bvh8Node* nodes, uint up, float3 lo, float3 hi) {
  global Bvh8Node* parent = nodes + up / RTCL_BLOCK_WIDTH;
  const uint lane = up % RTCL_BLOCK_WIDTH;
  parent->bounds[0][lane] = lo.x;
  parent->bounds[1][lane] = lo.y;
  parent->bounds[2][lane] = lo.z;
  parent->bounds[3][lane] = hi.x;
  parent->bounds[4][lane] = hi.y;
  parent->bounds[5][lane] = hi.z;
}

/* Node n (every lane written): its cost share into cost_parts[n], its box
 * into *lo, *hi. */
void finish_node(global Bvh8Node* nodes, uint n, float node_cost, global float* cost_parts, float3* lo, float3* hi) {
  volatile global const float* bounds = &nodes[n].bounds[0][0];
  global const int* child = nodes[n].child;
  float3 l = (float3)(INFINITY), h = (float3)(-INFINITY);
  float cost = 0.0f;
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
    const int c = child[lane];
    if (c == RTCL_CHILD_EMPTY) continue;
    const float3 a = (float3)(bounds[lane], bounds[RTCL_BLOCK_WIDTH + lane], bounds[2 * RTCL_BLOCK_WIDTH + lane]);
    const float3 b = (float3)(bounds[3 * RTCL_BLOCK_WIDTH + lane], bounds[4 * RTCL_BLOCK_WIDTH + lane],
                              bounds[5 * RTCL_BLOCK_WIDTH + lane]);
    cost += (c >= 0 ? node_cost : 1.0f) * box_area(a, b);
    l = min3(l, a);
    h = max3(h, b);
  }
  cost_parts[n] = cost;
  *lo = l;
  *hi = h;
}

/* After writing `count` lanes of node n: whether these writes are the last
 * of node n's arrivals[n] (then this work-item finishes n, and the counter
 * is back at 0 for the next refit). The fences order the lane writes
 * before the count and the count before the reads of n's lanes. */
inline bool last_to_arrive(global uint* counters, global const uint* arrivals, uint n, uint count) {
  mem_fence(CLK_GLOBAL_MEM_FENCE);
  if (atomic_add(counters + n, count) + count != arrivals[n]) return false;
  counters[n] = 0;
  mem_fence(CLK_GLOBAL_MEM_FENCE);
  return true;
}

kernel void refit_bottom_up(global TriangleBlock* blocks, global const uint* lane_vertices,
                            global const float* vertices, global Bvh8Node* nodes, global const uint* up,
                            global const uint* arrivals, global uint* counters, global const uint* block_nodes,
                            uint block_node_count, global const uint* start_nodes, uint start_count,
                            float node_cost, global float* cost_parts) {
  const uint i = get_global_id(0);
  float3 lo, hi;
  uint n;  /* the node to finish next */
  if (i < block_node_count) {
    n = block_nodes[i];
    uint filled = 0;
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
      const int c = nodes[n].child[lane];
      if (c >= 0 || c == RTCL_CHILD_EMPTY || (~c & 1) != 0) continue;  /* inner node, empty, sphere block */
      const uint b = (uint)(~c) >> 1;
      fill_block(blocks + b, lane_vertices + 3 * RTCL_BLOCK_WIDTH * b, vertices, &lo, &hi);
      write_lane(nodes, n * RTCL_BLOCK_WIDTH + lane, lo, hi);
      ++filled;
    }
    if (filled != arrivals[n] && !last_to_arrive(counters, arrivals, n, filled)) return;
  } else if (i < block_node_count + start_count) {
    n = start_nodes[i - block_node_count];
  } else {
    return;
  }
  for (;;) {
    finish_node(nodes, n, node_cost, cost_parts, &lo, &hi);
    const uint to = up[n];
    if (to == RTCL_REFIT_ROOT) return;
    write_lane(nodes, to, lo, hi);
    n = to / RTCL_BLOCK_WIDTH;
    if (!last_to_arrive(counters, arrivals, n, 1)) return;
  }
}
