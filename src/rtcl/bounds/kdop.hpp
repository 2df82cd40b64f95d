// Kay–Kajiya slabs / discrete oriented polytopes (k-DOP): the intersection
// of slabs d_near <= dot(n, x) <= d_far for a fixed set of unit directions n
// (Kay & Kajiya 1986; lecture, 非平行于坐标轴的包围盒: "project every vertex
// on N_i, take the smallest and largest distance").
//
// Direction sets (count = slabs; the k of "k-DOP" is twice that):
//   3  the axes (the AABB)
//   4  the four body diagonals (+-1, +-1, +-1)/sqrt(3)
//   7  axes + body diagonals (14-DOP)
//   9  axes + the six edge diagonals (+-1, +-1, 0)/sqrt(2), ... (18-DOP)
//   13 all of them (26-DOP)
#pragma once

#include <array>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/bounds/bounds_layouts.hpp"
#include "rtcl/geometry.hpp"

namespace rtcl {

struct Kdop {
  int count = 0;                             // directions in use
  std::array<glm::vec3, RTCL_MAX_SLABS> normal{};  // unit (as float), first `count` used
  std::array<float, RTCL_MAX_SLABS> d_near{}, d_far{};
  float reach = 0.0f;  // max |x| over the contents (SlabVolume::reach)

  SlabVolume record() const;
};

// The supported direction counts: 3, 4, 7, 9, 13.
const std::vector<int>& kdop_direction_counts();

// The unit directions of one set; throws Error naming the count otherwise.
std::vector<glm::vec3> kdop_directions(int count);

// Projects every point on each direction; d_near is rounded down and d_far
// up, so the float k-DOP contains every point. Throws like check_points.
Kdop kdop_of_points(const std::vector<glm::vec3>& points, int count, const std::string& source);

// A geometry's k-DOP: its used vertices by projection and its spheres in
// closed form (the lecture's Lagrange-multiplier case: the extremes of
// dot(n, x) on |x - c| = r are dot(n, c) -+ r |n|). Throws Error naming the
// source when there is nothing to bound.
Kdop kdop_of_geometry(const Geometry& geometry, int count);

}  // namespace rtcl
