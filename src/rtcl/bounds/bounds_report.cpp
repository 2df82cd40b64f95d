#include "rtcl/bounds/bounds_report.hpp"

#include <chrono>

#include "rtcl/bounds/point_input.hpp"
#include "rtcl/bounds/slab_measure.hpp"

namespace rtcl {

namespace {

template <class F>
auto timed(double* ms, F&& build) {
  auto start = std::chrono::steady_clock::now();
  auto result = build();
  *ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

BoundEntry sphere_entry(const std::string& name, const BoundingSphere& s, double ms) {
  BoundEntry e;
  e.name = name;
  e.sphere = true;
  e.ball = s.record();
  e.volume = s.volume();
  e.area = s.area();
  e.build_ms = ms;
  return e;
}

}  // namespace

BoundsReport report_bounds(const std::vector<glm::vec3>& points, const std::string& source) {
  check_points(points, source);
  BoundsReport r;
  r.point_count = points.size();
  double ms = 0.0;
  {
    Aabb box = timed(&ms, [&] {
      Aabb b;
      for (const glm::vec3& p : points) b.grow(p);
      return b;
    });
    BoundEntry e;
    e.name = "aabb";
    Kdop k;  // the AABB as a 3-slab record (axes exact, bounds exact floats)
    k.count = 3;
    for (int a = 0; a < 3; ++a) {
      k.normal[a] = glm::vec3(0.0f);
      k.normal[a][a] = 1.0f;
      k.d_near[a] = box.lower[a];
      k.d_far[a] = box.upper[a];
    }
    k.reach = reach_of(points);
    e.slabs = k.record();
    glm::dvec3 x = glm::dvec3(box.upper) - glm::dvec3(box.lower);
    e.volume = x.x * x.y * x.z;
    e.area = 2.0 * (x.x * x.y + x.y * x.z + x.z * x.x);
    e.build_ms = ms;
    r.entries.push_back(e);
  }
  r.obb = timed(&ms, [&] { return obb_of_points(points, source); });
  r.entries.push_back({"obb", false, r.obb.record(), {}, r.obb.volume(), r.obb.area(), ms});
  for (int count : kdop_direction_counts()) {
    if (count == 3) continue;  // the AABB above
    Kdop k = timed(&ms, [&] { return kdop_of_points(points, count, source); });
    BoundEntry e;
    e.name = "kdop" + std::to_string(count);
    e.slabs = k.record();
    VolumeMeasure m = measure_slabs(e.slabs);
    e.volume = m.volume;
    e.area = m.area;
    e.build_ms = ms;
    r.entries.push_back(e);
  }
  r.ritter = timed(&ms, [&] { return ritter_sphere(points, source); });
  r.entries.push_back(sphere_entry("ritter", r.ritter, ms));
  r.iterated = timed(&ms, [&] { return iterated_ritter_sphere(points, source); });
  r.entries.push_back(sphere_entry("iterated", r.iterated, ms));
  r.exact = timed(&ms, [&] { return exact_sphere(points, source); });
  r.entries.push_back(sphere_entry("exact", r.exact, ms));
  return r;
}

}  // namespace rtcl
