// The interface every acceleration structure implements: built over a
// Geometry, queried with Ray buffers, answering into Hit buffers. Callers
// never depend on which structure answers.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "rtcl/cl/device.hpp"
#include "rtcl/scene/geometry.hpp"

namespace rtcl {

enum class Query {
  closest,  // nearest hit in [tmin, tmax]
  any,      // some hit in [tmin, tmax] (occlusion); t and prim of that hit
};

struct AccelStats {
  double build_ms = 0.0;             // host build + flatten, without upload
  std::size_t device_bytes = 0;      // structure + primitive data on the device
  std::size_t primitive_count = 0;   // primitives stored (zero-area triangles skipped)
  std::size_t zero_area_skipped = 0;
  std::size_t node_count = 0;        // inner nodes (0 for brute force)
  std::size_t leaf_count = 0;        // primitive blocks
};

class Accel {
 public:
  virtual ~Accel() = default;
  Accel(const Accel&) = delete;
  Accel& operator=(const Accel&) = delete;

  const std::string& name() const { return name_; }
  const AccelStats& stats() const { return stats_; }
  const Device& device() const { return device_; }

  // Enqueues the query for rays[0 .. ray_count) into hits[0 .. ray_count) on
  // the device's queue after `wait`; returns the kernel's event. Throws Error
  // when a buffer is smaller than ray_count records. Not thread-safe per Accel.
  cl::Event trace(Query query, const cl::Buffer& rays, const cl::Buffer& hits, std::size_t ray_count,
                  const std::vector<cl::Event>& wait = {}) const;
  // The same on a caller's raw buffers (retained for the call, not owned):
  // for applications on the OpenCL C API.
  cl::Event trace(Query query, cl_mem rays, cl_mem hits, std::size_t ray_count,
                  const std::vector<cl::Event>& wait = {}) const;

 protected:
  // rays_per_work_item: consecutive rays one work-item of the kernel traces
  // (1, or 8 for a packet kernel); the launch covers ceil(ray_count / it).
  Accel(const Device& device, std::string name, const std::string& kernel_file, std::vector<std::string> defines,
        AccelStats stats, std::size_t rays_per_work_item = 1);
  // Sets the structure's kernel arguments, starting at argument `first`.
  virtual void set_structure_args(cl::Kernel& kernel, cl_uint first) const = 0;

 private:
  Device device_;
  std::string name_;
  AccelStats stats_;
  std::size_t rays_per_work_item_;
  mutable cl::Kernel closest_, any_;
  mutable bool args_set_ = false;
};

// Names make_accel accepts, in the order benchmarks list them.
std::vector<std::string> accel_names();

// Builds the named structure over validated geometry and uploads it.
// Throws Error naming the accel when the name is unknown.
std::unique_ptr<Accel> make_accel(const Device& device, std::string_view name, const Geometry& geometry);

// The -D options every trace program needs for this geometry.
std::vector<std::string> primitive_defines(const Geometry& geometry);

}  // namespace rtcl
