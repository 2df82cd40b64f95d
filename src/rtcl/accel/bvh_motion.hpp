// The 8-wide BVH over moving primitives (motion blur): every triangle and
// sphere has two keyframes, at shutter open and close, and a ray carries a
// time (a fraction of the shutter interval) at which the primitives lie at
// open + time * (close - open) (kernels/accel/bvh_motion.cl). The tree is
// built once (binned SAH over each primitive's swept box, the union of its
// two keyframe boxes) and its node bounds take one of two forms, measured
// against each other in bench/motion_bench.cpp.
#pragma once

#include <cstdint>
#include <memory>

#include "rtcl/accel.hpp"
#include "rtcl/geometry.hpp"

namespace rtcl {

enum class MotionBounds {
  swept,         // one box per child over the whole shutter: one box test per child, looser boxes
  interpolated,  // a box per child at open and at close, interpolated at the ray's time: tight boxes, twice the node bytes
};

// Per-ray times on the device: ray i's time is the float at index
// offset + i * stride of `buffer` (stride 1: a plain float array; a record
// array's float field: its size and offset in floats). Fractions of the
// shutter interval; clamped to [0, 1] by the kernel (NaN: 0).
struct RayTimes {
  cl::Buffer buffer;
  std::uint32_t stride = 1, offset = 0;
};

class MotionBvh final : public Accel {
 public:
  // Builds over `open` and `close`: the same primitives (same triangle
  // indices, same vertex and sphere counts) at shutter open and close.
  // Stored: every sphere and every triangle whose area at open is not zero
  // (a non-singular motion keeps zero areas zero). Throws Error naming
  // open.source when the two differ in topology or fail validate().
  MotionBvh(const Device& device, const Geometry& open, const Geometry& close, MotionBounds bounds,
            const AccelConfig& config = {});

  MotionBounds bounds() const { return bounds_; }

  // Accel::trace with each ray at its time. (Accel::trace without times
  // throws Error.)
  cl::Event trace(Query query, const cl::Buffer& rays, const RayTimes& times, const cl::Buffer& hits,
                  std::size_t ray_count, const std::vector<cl::Event>& wait = {},
                  Coherence coherence = Coherence::incoherent) const;

 // The host-side build (bvh_motion.cpp).
  struct Data;

 private:
  MotionBvh(const Device& device, std::unique_ptr<Data> data, MotionBounds bounds, const AccelConfig& config);
  void set_call_args(cl::Kernel& kernel) const override;
  void set_structure_args(cl::Kernel& kernel, cl_uint first) const override;

  MotionBounds bounds_;
  cl::Buffer nodes_, nodes_close_, tri_open_, tri_close_, sph_open_, sph_close_;
  mutable const RayTimes* times_ = nullptr;  // of the trace call in progress
};

// "swept" or "interpolated".
const char* motion_bounds_name(MotionBounds bounds);

}  // namespace rtcl
