#include "rtcl/accel/bvh_child_volumes.hpp"

#include <cfloat>
#include <cmath>
#include <numbers>

#include "rtcl/bounds/kdop.hpp"
#include "rtcl/bounds/obb.hpp"
#include "rtcl/bounds/point_input.hpp"
#include "rtcl/bounds/slab_measure.hpp"
#include "rtcl/bounds/sphere_bounds.hpp"
#include "rtcl/error.hpp"

namespace rtcl {

namespace {

// RTCL_VOLUME_WIDEN of kernels/shared/volumes.h: the filters' spatial
// margin per unit of (2 |o|_inf + reach); the host stores the reach part.
constexpr double kWiden = 16.0 * FLT_EPSILON;

// The OBB descent's finest rotation step for a filter (obb.hpp; the bounds
// report uses 1e-5): seven halvings from 0.25 rad instead of fifteen, about
// half the fit time, the box's orientation within ~1e-3 rad of a local
// optimum (a filter needs a tight box, not the tightest).
constexpr double kObbMinStep = 2e-3;

// The box's three axis slabs followed by `count` more.
SlabVolume box_and(const Aabb& box, int count, const glm::vec3* normal, const float* d_near, const float* d_far) {
  SlabVolume v{};
  v.count = 3 + count;
  for (int a = 0; a < 3; ++a) {
    v.normal[a][a] = 1.0f;
    v.d_near[a] = box.lower[a];
    v.d_far[a] = box.upper[a];
  }
  for (int i = 0; i < count; ++i) {
    for (int c = 0; c < 3; ++c) v.normal[3 + i][c] = normal[i][c];
    v.d_near[3 + i] = d_near[i];
    v.d_far[3 + i] = d_far[i];
  }
  return v;
}

void widen(float& d_near, float& d_far, double margin) {
  d_near = round_down(static_cast<double>(d_near) - margin);
  d_far = round_up(static_cast<double>(d_far) + margin);
}

// The kernel's diagonals (RTCL_KDOP_DIAGONAL, kdop_filter8.h) are kdop.cpp's
// 7-direction set after the axes: the records assume it.
const std::vector<glm::vec3>& diagonals() {
  static const std::vector<glm::vec3> d = [] {
    std::vector<glm::vec3> all = kdop_directions(7);
    std::vector<glm::vec3> out(all.begin() + 3, all.end());
    const float c = RTCL_KDOP_DIAGONAL;
    const glm::vec3 kernel[RTCL_KDOP_FILTER_SLABS] = {{c, c, c}, {c, c, -c}, {c, -c, c}, {-c, c, c}};
    for (int j = 0; j < RTCL_KDOP_FILTER_SLABS; ++j)
      if (out[static_cast<std::size_t>(j)] != kernel[j])
        throw Error("bvh-mixed: the k-DOP directions of kdop.cpp differ from the kernel's (kdop_filter8.h)");
    return out;
  }();
  return d;
}

}  // namespace

ChildVolumes child_volumes(const Aabb& box, const std::vector<glm::vec3>& points, const std::string& source) {
  ChildVolumes v;
  v.box_area = measure_slabs(box_and(box, 0, nullptr, nullptr, nullptr)).area;

  BoundingSphere s = exact_sphere(points, source);
  double r = static_cast<double>(s.radius) + kWiden * static_cast<double>(s.reach);
  float rf = round_up(r);
  double sphere_area = 4.0 * std::numbers::pi * static_cast<double>(rf) * rf;
  v.sphere[0] = s.center.x;
  v.sphere[1] = s.center.y;
  v.sphere[2] = s.center.z;
  v.sphere[3] = rf;
  v.used[RTCL_FILTER_SPHERE] = sphere_area < v.box_area;
  v.area[RTCL_FILTER_SPHERE] = std::fmin(sphere_area, v.box_area);

  Kdop k = kdop_of_points(points, 7, source);
  for (int j = 0; j < RTCL_KDOP_FILTER_SLABS; ++j) {
    v.kdop_near[j] = k.d_near[3 + j];
    v.kdop_far[j] = k.d_far[3 + j];
    widen(v.kdop_near[j], v.kdop_far[j], kWiden * static_cast<double>(k.reach));
  }
  double kdop_area = measure_slabs(box_and(box, 4, diagonals().data(), v.kdop_near, v.kdop_far)).area;
  v.used[RTCL_FILTER_KDOP] = kdop_area < v.box_area;
  v.area[RTCL_FILTER_KDOP] = std::fmin(kdop_area, v.box_area);

  Obb o = obb_of_points(points, source, kObbMinStep);
  for (int i = 0; i < 3; ++i) {
    for (int c = 0; c < 3; ++c) v.obb_axis[3 * i + c] = o.axis[i][c];
    v.obb_near[i] = o.d_near[i];
    v.obb_far[i] = o.d_far[i];
    widen(v.obb_near[i], v.obb_far[i], kWiden * static_cast<double>(o.reach));
  }
  double obb_area = measure_slabs(box_and(box, 3, o.axis, v.obb_near, v.obb_far)).area;
  v.used[RTCL_FILTER_OBB] = obb_area < v.box_area;
  v.area[RTCL_FILTER_OBB] = std::fmin(obb_area, v.box_area);
  return v;
}

void write_sphere_lane(Bvh8Spheres& record, int lane, const ChildVolumes* v) {
  bool on = v != nullptr && v->used[RTCL_FILTER_SPHERE];
  record.cx[lane] = on ? v->sphere[0] : 0.0f;
  record.cy[lane] = on ? v->sphere[1] : 0.0f;
  record.cz[lane] = on ? v->sphere[2] : 0.0f;
  record.r[lane] = on ? v->sphere[3] : -1.0f;
}

void write_kdop_lane(Bvh8Kdop& record, int lane, const ChildVolumes* v) {
  bool on = v != nullptr && v->used[RTCL_FILTER_KDOP];
  for (int j = 0; j < RTCL_KDOP_FILTER_SLABS; ++j) {
    record.d_near[j][lane] = on ? v->kdop_near[j] : -FLT_MAX;
    record.d_far[j][lane] = on ? v->kdop_far[j] : FLT_MAX;
  }
}

void write_obb_lane(Bvh8Obb& record, int lane, const ChildVolumes* v) {
  bool on = v != nullptr && v->used[RTCL_FILTER_OBB];
  const ChildVolumes identity;
  const ChildVolumes& src = on ? *v : identity;
  for (int i = 0; i < 9; ++i) record.axis[i][lane] = src.obb_axis[i];
  for (int i = 0; i < 3; ++i) {
    record.d_near[i][lane] = on ? v->obb_near[i] : -FLT_MAX;
    record.d_far[i][lane] = on ? v->obb_far[i] : FLT_MAX;
  }
}

}  // namespace rtcl
