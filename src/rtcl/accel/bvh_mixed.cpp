#include "rtcl/accel/bvh_mixed.hpp"

#include <chrono>

#include "rtcl/accel/bvh.hpp"
#include "rtcl/accel/primitive_blocks.hpp"

namespace rtcl {

namespace {

class MixedBvhAccel final : public Accel {
 public:
  MixedBvhAccel(const Device& device, std::vector<std::string> defines, const Bvh8& bvh,
                const BvhSphereFilters& filters, AccelStats stats, const AccelConfig& config)
      : Accel(device, "bvh-mixed", TraceKernels{"accel/bvh.cl"}, std::nullopt, std::move(defines), stats, config),
        nodes_(device.upload(bvh.nodes.data(), bvh.nodes.size() * sizeof(Bvh8Node), "BVH nodes")),
        primitives_(upload(device, bvh.blocks)),
        filtered_(!filters.records.empty()) {
    if (!filtered_) return;
    sphere_of_ = device.upload(filters.sphere_of.data(), filters.sphere_of.size() * sizeof(rtcl_i32), "BVH sphere indices");
    records_ = device.upload(filters.records.data(), filters.records.size() * sizeof(Bvh8Spheres), "BVH spheres");
  }

 private:
  void set_structure_args(cl::Kernel& kernel, cl_uint first) const override {
    kernel.setArg(first, nodes_);
    kernel.setArg(first + 1, primitives_.triangles);
    kernel.setArg(first + 2, primitives_.spheres);
    if (!filtered_) return;
    kernel.setArg(first + 3, sphere_of_);
    kernel.setArg(first + 4, records_);
  }

  cl::Buffer nodes_;
  DevicePrimitives primitives_;
  bool filtered_;
  cl::Buffer sphere_of_, records_;
};

}  // namespace

const StructureSpec& bvh_mixed_structure() {
  static const StructureSpec spec = [] {
    StructureSpec s{"bvh-mixed", "the bvh with a per-node choice of boxes alone or boxes then bounding spheres "
                                 "(expected cost, surface-area based); one ray per work-item",
                    bvh_sah_options()};
    s.options.push_back({"sphere_cost", OptionType::real, double{VolumeCosts{}.sphere}, 0, 64, false,
                         "cost of a node's eight-sphere filter relative to its eight-box test (measured on PoCL: "
                         "1.36); 0 puts spheres wherever they are smaller than the box, large values none"});
    s.options.push_back({"block_cost", OptionType::real, double{VolumeCosts{}.block}, 0, 64, false,
                         "cost of one leaf block (eight triangle tests) relative to a node's box test (measured "
                         "on PoCL: 8.1)"});
    return s;
  }();
  return spec;
}

std::unique_ptr<Accel> make_bvh_mixed(const Device& device, const Geometry& geometry, const AccelConfig& config) {
  auto start = std::chrono::steady_clock::now();
  BvhConfig bvh_config = resolve_bvh_config(bvh_mixed_structure(), config);
  AccelOptions o = resolve_options(bvh_mixed_structure(), config.options, "--accel bvh-mixed");
  VolumeCosts costs;
  costs.sphere = static_cast<float>(o.real("sphere_cost"));
  costs.block = static_cast<float>(o.real("block_cost"));
  GeometryReport report = validate(geometry);
  Bvh8 bvh = flatten_bvh8(build_binary_bvh(geometry, bvh_config), geometry, bvh_config.merge_leaves);
  BvhSphereFilters filters = choose_sphere_filters(bvh, costs, geometry.source);
  AccelStats stats = bvh_stats(geometry, report, bvh, start);
  if (!filters.records.empty())
    stats.device_bytes +=
        filters.sphere_of.size() * sizeof(rtcl_i32) + filters.records.size() * sizeof(Bvh8Spheres);
  std::vector<std::string> defines = bvh_defines(geometry, bvh);
  if (!filters.records.empty()) defines.push_back("RTCL_BVH_SPHERES");
  return std::make_unique<MixedBvhAccel>(device, std::move(defines), bvh, filters, stats, config);
}

}  // namespace rtcl
