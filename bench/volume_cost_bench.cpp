// Relative cost of the per-node tests the mixed-volume BVH chooses between
// (VolumeCosts in src/rtcl/accel/bvh_volumes.hpp): one node's eight-box
// slab test, its eight-sphere, 14-DOP-diagonal and OBB filters, and one
// eight-triangle leaf block, each
// run by bench/kernels/volume_costs.cl over the bunny BVH's first records for
// the bunny's diffuse rays. Counter ns_per_test: kernel time / (rays x records).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>

#include "bench/support/bench_kernels.hpp"
#include "bench_scenes.hpp"
#include "rtcl/accel/bvh.hpp"
#include "rtcl/device.hpp"

namespace rtcl::bench {
namespace {

// Child `lane`'s box of a node as centre and half extent (both 0 for an
// empty slot); returns whether the slot is empty.
bool lane_box(const Bvh8Node& node, int lane, glm::vec3* mid, glm::vec3* half) {
  const auto& b = node.bounds;
  bool empty = node.child[lane] == RTCL_CHILD_EMPTY;
  glm::vec3 lo(b[0][lane], b[1][lane], b[2][lane]), hi(b[3][lane], b[4][lane], b[5][lane]);
  *mid = empty ? glm::vec3(0.0f) : 0.5f * (lo + hi);
  *half = empty ? glm::vec3(0.0f) : 0.5f * (hi - lo);
  return empty;
}

// Spheres for timing only: each lane's box's circumscribed sphere.
std::vector<Bvh8Spheres> box_spheres(const std::vector<Bvh8Node>& nodes) {
  std::vector<Bvh8Spheres> out(nodes.size());
  for (std::size_t n = 0; n < nodes.size(); ++n)
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
      glm::vec3 c, half;
      bool empty = lane_box(nodes[n], lane, &c, &half);
      out[n].cx[lane] = c.x;
      out[n].cy[lane] = c.y;
      out[n].cz[lane] = c.z;
      out[n].r[lane] = empty ? -1.0f : glm::length(half);
    }
  return out;
}

// k-DOP and OBB records for timing only: each lane's box's own diagonal
// slabs, and an OBB about the box's centre turned by 0.5 rad about z
// (the filters have no data-dependent branches).
std::vector<Bvh8Kdop> box_kdops(const std::vector<Bvh8Node>& nodes) {
  const float c = RTCL_KDOP_DIAGONAL;
  const glm::vec3 dirs[RTCL_KDOP_FILTER_SLABS] = {{c, c, c}, {c, c, -c}, {c, -c, c}, {-c, c, c}};
  std::vector<Bvh8Kdop> out(nodes.size());
  for (std::size_t n = 0; n < nodes.size(); ++n)
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
      glm::vec3 mid, half;
      lane_box(nodes[n], lane, &mid, &half);
      for (int j = 0; j < RTCL_KDOP_FILTER_SLABS; ++j) {
        float centre = glm::dot(dirs[j], mid), extent = glm::dot(glm::abs(dirs[j]), half);
        out[n].d_near[j][lane] = centre - extent;
        out[n].d_far[j][lane] = centre + extent;
      }
    }
  return out;
}

std::vector<Bvh8Obb> box_obbs(const std::vector<Bvh8Node>& nodes) {
  const float cs = std::cos(0.5f), sn = std::sin(0.5f);
  const glm::vec3 axes[3] = {{cs, sn, 0.0f}, {-sn, cs, 0.0f}, {0.0f, 0.0f, 1.0f}};
  std::vector<Bvh8Obb> out(nodes.size());
  for (std::size_t n = 0; n < nodes.size(); ++n)
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
      glm::vec3 mid, half;
      lane_box(nodes[n], lane, &mid, &half);
      for (int i = 0; i < 3; ++i) {
        for (int k = 0; k < 3; ++k) out[n].axis[3 * i + k][lane] = axes[i][k];
        float centre = glm::dot(axes[i], mid), extent = glm::dot(glm::abs(axes[i]), half);
        out[n].d_near[i][lane] = centre - extent;
        out[n].d_far[i][lane] = centre + extent;
      }
    }
  return out;
}

void volume_cost(benchmark::State& state, const char* kernel_name) {
  try {
    auto scene = bench_scene("bunny");
    const Device& device = bench_device();
    Bvh8 bvh = flatten_bvh8(build_binary_bvh(scene->geometry), scene->geometry);
    const std::size_t count = std::min<std::size_t>({256, bvh.nodes.size(), bvh.blocks.triangles.size()});
    std::vector<Ray> rays = scene->diffuse.rays;
    rays.resize(std::min<std::size_t>(rays.size(), 65536));
    std::vector<Bvh8Spheres> spheres = box_spheres(bvh.nodes);
    cl::Buffer ray_buffer = device.upload(rays.data(), rays.size() * sizeof(Ray), "rays");
    cl::Buffer records;
    std::string kernel(kernel_name);
    if (kernel == "cost_boxes8")
      records = device.upload(bvh.nodes.data(), count * sizeof(Bvh8Node), "nodes");
    else if (kernel == "cost_spheres8")
      records = device.upload(spheres.data(), count * sizeof(Bvh8Spheres), "spheres");
    else if (kernel == "cost_kdop8")
      records = device.upload(box_kdops(bvh.nodes).data(), count * sizeof(Bvh8Kdop), "k-DOPs");
    else if (kernel == "cost_obb8")
      records = device.upload(box_obbs(bvh.nodes).data(), count * sizeof(Bvh8Obb), "OBBs");
    else
      records = device.upload(bvh.blocks.triangles.data(), count * sizeof(TriangleBlock), "blocks");
    cl::Buffer out = device.allocate(rays.size() * sizeof(cl_int), "counts");
    cl::Kernel k(bench_program(device, "volume_costs.cl"), kernel_name);
    k.setArg(0, ray_buffer);
    k.setArg(1, records);
    k.setArg(2, static_cast<cl_uint>(count));
    k.setArg(3, out);
    for (auto _ : state) {
      cl::Event done;
      device.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(rays.size()), cl::NullRange, nullptr, &done);
      done.wait();
      auto start = done.getProfilingInfo<CL_PROFILING_COMMAND_START>();
      auto end = done.getProfilingInfo<CL_PROFILING_COMMAND_END>();
      double seconds = static_cast<double>(end - start) * 1e-9;
      state.SetIterationTime(seconds);
      state.counters["ns_per_test"] = seconds * 1e9 / (static_cast<double>(rays.size()) * static_cast<double>(count));
    }
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

[[maybe_unused]] const bool volume_cost_registered = [] {
  for (const char* kernel : {"cost_boxes8", "cost_spheres8", "cost_kdop8", "cost_obb8", "cost_triangles8"})
    benchmark::RegisterBenchmark((std::string("volume_cost/bunny/") + kernel).c_str(), volume_cost, kernel)
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond);
  return true;
}();

}  // namespace
}  // namespace rtcl::bench
