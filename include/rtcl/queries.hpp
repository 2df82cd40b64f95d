// Public API: the host-array inputs and the answers of the queries
// (docs/api.md). The records Ray, Hit and PointHit are shared with the
// kernels (rtcl/shared/query_layouts.h): arrays of 4-byte fields, no padding,
// the same bytes as the ray and hit files.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/shared/query_layouts.h"

namespace rtcl {

enum class Query {
  closest,  // nearest hit in [tmin, tmax]
  any,      // some hit in [tmin, tmax] (occlusion); t and prim of that hit
};

inline constexpr float kUnlimitedDistance = std::numeric_limits<float>::infinity();
// Accel::all_hits without a cap per ray.
inline constexpr std::uint32_t kAllHitsUnlimited = 0xffffffffu;

// Host rays, as Ray records or as separate arrays: origins and directions
// (3 floats per ray, x y z) with optional tmin and tmax (1 float per ray;
// absent: 0 and +inf). A view: the arrays must outlive the call that reads
// them. Sizes are checked by the query that receives it.
class Rays {
 public:
  Rays(std::span<const Ray> records) : records_(records), count_(records.size()) {}
  Rays(const std::vector<Ray>& records) : Rays(std::span<const Ray>(records)) {}
  Rays(std::span<const float> origins, std::span<const float> directions, std::span<const float> tmin = {},
       std::span<const float> tmax = {});

  std::size_t size() const { return count_; }
  // Whether the rays are Ray records (records()), else separate arrays.
  bool are_records() const { return count_ == 0 || !records_.empty(); }
  std::span<const Ray> records() const { return records_; }
  // Copies rays [first, first + out.size()) into out as records.
  void pack(std::size_t first, std::span<Ray> out) const;

 private:
  std::span<const Ray> records_;
  std::span<const float> origins_, directions_, tmin_, tmax_;
  std::size_t count_ = 0;
};

// Host query points: 3 floats per point (x y z), or glm::vec3s. A view.
class Points {
 public:
  Points(std::span<const float> xyz);
  Points(std::span<const glm::vec3> points)
      : xyz_(points.empty() ? nullptr : &points[0].x, points.size() * 3), count_(points.size()) {}
  Points(const std::vector<glm::vec3>& points) : Points(std::span<const glm::vec3>(points)) {}

  std::size_t size() const { return count_; }
  std::span<const float> xyz() const { return xyz_; }

 private:
  std::span<const float> xyz_;
  std::size_t count_ = 0;
};

// Every hit of every ray, compressed: ray i's hits are
// hits[offsets[i] .. offsets[i + 1]), sorted by t (ties: smaller prim
// first). offsets has rays + 1 entries, offsets[0] = 0.
struct AllHits {
  std::vector<std::uint64_t> offsets;
  std::vector<Hit> hits;
  std::size_t ray_count() const { return offsets.empty() ? 0 : offsets.size() - 1; }
  std::span<const Hit> of_ray(std::size_t ray) const {
    return std::span<const Hit>(hits).subspan(offsets[ray], offsets[ray + 1] - offsets[ray]);
  }
};

}  // namespace rtcl
