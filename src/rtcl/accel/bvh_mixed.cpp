#include "rtcl/accel/bvh_mixed.hpp"
#include "rtcl/accel/structure_kernels.hpp"

#include <chrono>

#include "rtcl/accel/bvh.hpp"
#include "rtcl/accel/primitive_blocks.hpp"

namespace rtcl {

namespace {

class MixedBvhAccel final : public Accel {
 public:
  MixedBvhAccel(const Device& device, std::vector<std::string> defines, const Bvh8& bvh, std::size_t occluder_run,
                const BvhVolumeFilters& filters, AccelStats stats, const AccelConfig& config)
      : Accel(device, "bvh-mixed", TraceKernels{"accel/bvh.cl", 1, occluder_run}, std::nullopt, std::move(defines),
              stats, config),
        nodes_(device.upload(bvh.nodes.data(), bvh.nodes.size() * sizeof(Bvh8Node), "BVH nodes")),
        primitives_(upload(device, bvh.blocks)) {
    if (filters.empty()) return;
    filter_of_ = device.upload(filters.filter_of.data(), filters.filter_of.size() * sizeof(rtcl_i32), "BVH filter indices");
    if (!filters.spheres.empty())
      records_.push_back(device.upload(filters.spheres.data(), filters.spheres.size() * sizeof(Bvh8Spheres), "BVH spheres"));
    if (!filters.kdops.empty())
      records_.push_back(device.upload(filters.kdops.data(), filters.kdops.size() * sizeof(Bvh8Kdop), "BVH k-DOPs"));
    if (!filters.obbs.empty())
      records_.push_back(device.upload(filters.obbs.data(), filters.obbs.size() * sizeof(Bvh8Obb), "BVH OBBs"));
  }

 private:
  // Arguments after the primitives: filter_of, then the record array of
  // each kind present, in RTCL_FILTER_* order (kernels/accel/bvh.cl).
  void set_structure_args(cl::Kernel& kernel, cl_uint first) const override {
    kernel.setArg(first, nodes_);
    kernel.setArg(first + 1, primitives_.triangles);
    kernel.setArg(first + 2, primitives_.spheres);
    if (records_.empty()) return;
    kernel.setArg(first + 3, filter_of_);
    for (std::size_t i = 0; i < records_.size(); ++i) kernel.setArg(first + 4 + static_cast<cl_uint>(i), records_[i]);
  }

  cl::Buffer nodes_;
  DevicePrimitives primitives_;
  cl::Buffer filter_of_;
  std::vector<cl::Buffer> records_;
};

}  // namespace

const StructureSpec& bvh_mixed_structure() {
  static const StructureSpec spec = [] {
    StructureSpec s{"bvh-mixed", "the bvh with a per-node choice of boxes alone or boxes then bounding spheres, "
                                 "14-DOP slabs or oriented boxes (expected cost, surface-area based); one ray per "
                                 "work-item",
                    bvh_sah_options()};
    const VolumeCosts d;
    s.options.push_back({"sphere_cost", OptionType::real, double{d.sphere}, 0, 64, false,
                         "cost of a node's eight-sphere filter relative to its eight-box test; 0 puts spheres "
                         "wherever they are smaller than the box, large values none"});
    s.options.push_back({"kdop_cost", OptionType::real, double{d.kdop}, 0, 64, false,
                         "cost of a node's eight 14-DOP diagonal-slab filter relative to its eight-box test; 0 "
                         "puts it wherever it cuts the box, large values nowhere"});
    s.options.push_back({"obb_cost", OptionType::real, double{d.obb}, 0, 64, false,
                         "cost of a node's eight-OBB filter relative to its eight-box test; 0 puts it wherever it "
                         "cuts the box, large values nowhere"});
    s.options.push_back({"block_cost", OptionType::real, double{d.block}, 0, 64, false,
                         "cost of one leaf block (eight triangle tests) relative to a node's box test"});
    return s;
  }();
  return spec;
}

std::unique_ptr<Accel> make_bvh_mixed(const Device& device, const Geometry& geometry, const AccelConfig& config) {
  auto start = std::chrono::steady_clock::now();
  BvhConfig bvh_config = bvh_config_from(config.options);
  const AccelOptions& o = config.options;
  VolumeCosts costs;
  costs.sphere = static_cast<float>(o.real("sphere_cost"));
  costs.kdop = static_cast<float>(o.real("kdop_cost"));
  costs.obb = static_cast<float>(o.real("obb_cost"));
  costs.block = static_cast<float>(o.real("block_cost"));
  GeometryReport report = validate(geometry);
  Bvh8 bvh = flatten_bvh8(build_binary_bvh(geometry, bvh_config), geometry, flatten_options(bvh_config));
  BvhVolumeFilters filters = choose_volume_filters(bvh, costs, geometry.source);
  AccelStats stats = bvh_stats(geometry, report, bvh, start);
  stats.device_bytes += filters.device_bytes();
  std::vector<std::string> defines = bvh_defines(geometry, bvh);
  if (!filters.spheres.empty()) defines.push_back("RTCL_BVH_SPHERES");
  if (!filters.kdops.empty()) defines.push_back("RTCL_BVH_KDOP");
  if (!filters.obbs.empty()) defines.push_back("RTCL_BVH_OBB");
  return std::make_unique<MixedBvhAccel>(device, std::move(defines), bvh, occluder_run_for(bvh_config.occluder_run, device.info()),
                                         filters, stats, config);
}

}  // namespace rtcl
