/* Refit of the 8-wide BVH (src/rtcl/accel/refit.hpp): the tree keeps its
 * shape, the triangle blocks are filled again from new vertices and every
 * node's child boxes are recomputed bottom-up (Bvh8Node, TriangleBlock:
 * shared/layouts.h).
 *
 * Lane vertices: lane_vertices[24 b + 8 k + lane] is the index of corner k
 * (0..2) of the triangle in lane `lane` of triangle block b, or
 * RTCL_REFIT_NO_LANE for an unused lane. refit_lane_vertices makes it from
 * the triangles' indices when they are new; then each refit reads the
 * corners' indices in block order, not through the triangles.
 *
 * 1. refit_triangle_lanes, one work-item per lane: the lane's corners from
 *    the vertices (consecutive work-items write consecutive floats).
 * 2. Nodes level by level, deepest first (order[] holds the node indices
 *    grouped by wide depth, deepest level first; level_begin[l] ..
 *    level_begin[l + 1] is level l of that order): an inner child's lane
 *    becomes the union of that child's eight lanes, a triangle block's lane
 *    the box of its corners (unused lanes are NaN, which fmin and fmax
 *    ignore); a sphere block's lane stays as built. refit_nodes covers one
 *    level with one work-item per node; refit_levels covers several small
 *    levels in one work-group, a barrier between levels.
 *
 * Boxes are the exact float minima and maxima of the corners (no
 * rounding), so every lane's box contains what lies below it. Each node
 * also writes its share of the tree's SAH cost to cost_parts[node]: the
 * sum over its used lanes of the lane box's area, times node_cost for an
 * inner child, times 1 for a block (refit.cpp sums them). */
#include "shared/layouts.h"

#define RTCL_REFIT_NO_LANE 0xffffffffu

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

kernel void refit_triangle_lanes(global TriangleBlock* blocks, uint lane_count, global const uint* lane_vertices,
                                 global const float* vertices) {
  const uint i = get_global_id(0);
  if (i >= lane_count) return;
  const uint b = i / RTCL_BLOCK_WIDTH, lane = i % RTCL_BLOCK_WIDTH;
  global const uint* corners = lane_vertices + 3 * RTCL_BLOCK_WIDTH * b + lane;
  const uint i0 = corners[0], i1 = corners[RTCL_BLOCK_WIDTH], i2 = corners[2 * RTCL_BLOCK_WIDTH];
  if (i0 == RTCL_REFIT_NO_LANE) return;
  const float3 a = vload3(i0, vertices), c1 = vload3(i1, vertices), c2 = vload3(i2, vertices);
  global TriangleBlock* block = blocks + b;
  block->v[0][0][lane] = a.x;
  block->v[0][1][lane] = a.y;
  block->v[0][2][lane] = a.z;
  block->v[1][0][lane] = c1.x;
  block->v[1][1][lane] = c1.y;
  block->v[1][2][lane] = c1.z;
  block->v[2][0][lane] = c2.x;
  block->v[2][1][lane] = c2.y;
  block->v[2][2][lane] = c2.z;
}

float min8(float8 v) {
  const float4 m = fmin(v.lo, v.hi);
  const float2 n = fmin(m.lo, m.hi);
  return fmin(n.x, n.y);
}

float max8(float8 v) {
  const float4 m = fmax(v.lo, v.hi);
  const float2 n = fmax(m.lo, m.hi);
  return fmax(n.x, n.y);
}

float box_area(float3 lo, float3 hi) {
  const float3 e = hi - lo;
  return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
}

/* Node n's lanes from their children's lanes and blocks; its cost share. */
void refit_node(global Bvh8Node* nodes, global const TriangleBlock* blocks, uint n, float node_cost,
                global float* cost_parts) {
  global Bvh8Node* node = nodes + n;
  float cost = 0.0f;
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
    const int c = node->child[lane];
    if (c == RTCL_CHILD_EMPTY) continue;
    float3 lo, hi;
    float weight = 1.0f;
    if (c >= 0) {
      global const float* rows = &nodes[c].bounds[0][0];
      lo = (float3)(min8(vload8(0, rows)), min8(vload8(1, rows)), min8(vload8(2, rows)));
      hi = (float3)(max8(vload8(3, rows)), max8(vload8(4, rows)), max8(vload8(5, rows)));
      weight = node_cost;
    } else if ((~c & 1) == 0) {
      /* rows 3 k + axis: corner k's coordinate `axis` of the block's lanes */
      global const float* rows = &blocks[(uint)~c >> 1].v[0][0][0];
      float8 x0 = vload8(0, rows), y0 = vload8(1, rows), z0 = vload8(2, rows);
      float8 x1 = vload8(3, rows), y1 = vload8(4, rows), z1 = vload8(5, rows);
      float8 x2 = vload8(6, rows), y2 = vload8(7, rows), z2 = vload8(8, rows);
      lo = (float3)(min8(fmin(x0, fmin(x1, x2))), min8(fmin(y0, fmin(y1, y2))), min8(fmin(z0, fmin(z1, z2))));
      hi = (float3)(max8(fmax(x0, fmax(x1, x2))), max8(fmax(y0, fmax(y1, y2))), max8(fmax(z0, fmax(z1, z2))));
    } else {
      lo = (float3)(node->bounds[0][lane], node->bounds[1][lane], node->bounds[2][lane]);
      hi = (float3)(node->bounds[3][lane], node->bounds[4][lane], node->bounds[5][lane]);
      cost += box_area(lo, hi);
      continue;
    }
    node->bounds[0][lane] = lo.x;
    node->bounds[1][lane] = lo.y;
    node->bounds[2][lane] = lo.z;
    node->bounds[3][lane] = hi.x;
    node->bounds[4][lane] = hi.y;
    node->bounds[5][lane] = hi.z;
    cost += weight * box_area(lo, hi);
  }
  cost_parts[n] = cost;
}

/* order[first .. first + count): one level, one node per work-item. */
kernel void refit_nodes(global Bvh8Node* nodes, global const TriangleBlock* blocks, global const uint* order,
                        uint first, uint count, float node_cost, global float* cost_parts) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  refit_node(nodes, blocks, order[first + i], node_cost, cost_parts);
}

/* Levels first_level .. end_level - 1 in turn, by one work-group. */
kernel void refit_levels(global Bvh8Node* nodes, global const TriangleBlock* blocks, global const uint* order,
                         global const uint* level_begin, uint first_level, uint end_level, float node_cost,
                         global float* cost_parts) {
  for (uint level = first_level; level < end_level; ++level) {
    const uint end = level_begin[level + 1];
    for (uint i = level_begin[level] + get_local_id(0); i < end; i += get_local_size(0))
      refit_node(nodes, blocks, order[i], node_cost, cost_parts);
    barrier(CLK_GLOBAL_MEM_FENCE);
  }
}
