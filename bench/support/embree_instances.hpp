// Embree 3's instancing as the yardstick of rtcl::Scene: one child scene of
// a mesh (committed once, timed apart, as rtcl's bottom level) and a top
// scene of RTC_GEOMETRY_TYPE_INSTANCE geometries over it, traced with
// rtcIntersect1 on host threads over rtcl's Ray records. Part of
// rtcl_embree (built only when CMake finds Embree 3); used by
// bench/scenes/instances_bench.cpp and `rtcl bench --instances`.
#pragma once

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "rtcl/geometry.hpp"
#include "rtcl/layouts.hpp"
#include "rtcl/scene.hpp"

namespace rtcl::bench {

// One ray's answer: the instance (its index among the placements) and the
// triangle within the mesh; prim -1 for a miss.
struct InstanceHit {
  std::uint32_t instance = 0;
  std::int32_t prim = -1;
};

class EmbreeInstances {
 public:
  // An Embree device of `threads` threads and the committed child scene.
  EmbreeInstances(const Geometry& mesh, unsigned threads);
  ~EmbreeInstances();
  EmbreeInstances(const EmbreeInstances&) = delete;
  EmbreeInstances& operator=(const EmbreeInstances&) = delete;

  // The child scene's rtcCommitScene, ms.
  double child_ms() const { return child_ms_; }

  // A new top scene of the placements (instance k: placements[k]): the ms
  // of its geometry setup and of its rtcCommitScene.
  std::pair<double, double> place(const std::vector<Transform>& placements);

  // rtcIntersect1 over `rays` (converted into Embree's records before the
  // clock starts) on the device's threads in blocks of 4096 rays: the ms of
  // the traversal; the answers into *hits when given.
  double trace(const std::vector<Ray>& rays, std::vector<InstanceHit>* hits = nullptr) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double child_ms_ = 0.0;
};

}  // namespace rtcl::bench
