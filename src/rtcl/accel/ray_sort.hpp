// The device sort of a Coherence::scattered trace call (kernels/accel/ray_sort.cl):
// rays reordered by the Morton code of their origin's cell on a coarse grid
// over the scene's box and their direction's octant, so that rays traced one
// after another visit the same nodes. Accel::trace then traces ray order()[k]
// k-th and writes its hit at that index; the ray records are not moved.
#pragma once

#include <cstddef>
#include <vector>

#include "rtcl/aabb.hpp"
#include "rtcl/device.hpp"

namespace rtcl {

class RaySort {
 public:
  // Origins binned on 2^origin_bits cells per axis over `bounds` (an empty
  // box: the octant alone); 0 .. 4, else Error. The default 3 sorts the
  // bench/ scenes' bounces fastest (docs/benchmarks.md).
  RaySort(const Device& device, const Aabb& bounds, int origin_bits = 3);

  // Enqueues the sort of rays[0 .. ray_count), ray_count >= 1 (else Error;
  // Accel::trace sorts no empty call), after `wait`; returns the
  // events of its passes in order (the first starts the call's device
  // time). Then order() holds the ray indices sorted by key, equal keys in
  // their input order.
  std::vector<cl::Event> enqueue(const cl::Buffer& rays, std::size_t ray_count, const std::vector<cl::Event>& wait);

  const cl::Buffer& order() const { return order_; }

 private:
  void reserve(std::size_t ray_count, std::size_t chunks);

  Device device_;
  cl_float4 lo_{}, scale_{};
  std::size_t buckets_;
  cl::Kernel count_, offsets_, scatter_;
  cl::Buffer counts_, totals_, keys_, order_;
  std::size_t ray_capacity_ = 0, chunk_capacity_ = 0;
};

}  // namespace rtcl
