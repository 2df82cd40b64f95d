// Brute force: all primitives in id order, tested eight at a time. The
// device-side reference every other structure is compared with.
#include "rtcl/accel/brute.hpp"
#include "rtcl/accel/structure_kernels.hpp"

#include <chrono>

#include "rtcl/accel/primitive_blocks.hpp"

namespace rtcl {

namespace {

class BruteAccel final : public Accel {
 public:
  BruteAccel(const Device& device, const Geometry& geometry, PrimitiveBlocks blocks, AccelStats stats,
             const AccelConfig& config)
      : Accel(device, "brute", {"accel/brute.cl"}, std::nullopt, primitive_defines(geometry), stats, config),
        primitives_(upload(device, blocks)),
        triangle_blocks_(static_cast<cl_uint>(blocks.triangles.size())),
        sphere_blocks_(static_cast<cl_uint>(blocks.spheres.size())) {}

 private:
  void set_structure_args(cl::Kernel& kernel, cl_uint first) const override {
    kernel.setArg(first, primitives_.triangles);
    kernel.setArg(first + 1, triangle_blocks_);
    kernel.setArg(first + 2, primitives_.spheres);
    kernel.setArg(first + 3, sphere_blocks_);
  }

  DevicePrimitives primitives_;
  cl_uint triangle_blocks_, sphere_blocks_;
};

}  // namespace

const StructureSpec& brute_structure() {
  static const StructureSpec spec{"brute", "every ray against every primitive, 8 per block (the device reference)", {}};
  return spec;
}

std::unique_ptr<Accel> make_brute(const Device& device, const Geometry& geometry, const AccelConfig& config) {
  auto start = std::chrono::steady_clock::now();
  GeometryReport report = validate(geometry);
  std::vector<std::uint32_t> ids = stored_primitives(geometry);
  PrimitiveBlocks blocks = in_order_blocks(geometry, ids);
  AccelStats stats;
  stats.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  stats.device_bytes = blocks.bytes();
  stats.primitive_count = ids.size();
  stats.zero_area_skipped = report.zero_area_triangles;
  stats.bounds = geometry.bounds();
  stats.leaf_count = blocks.triangles.size() + blocks.spheres.size();
  return std::make_unique<BruteAccel>(device, geometry, std::move(blocks), stats, config);
}

}  // namespace rtcl
