#include "rtcl/scene/mesh_refit.hpp"

#include <utility>
#include <vector>

#include "rtcl/accel/refit.hpp"
#include "rtcl/error.hpp"

namespace rtcl {

MeshRefit refit_mesh(const MeshBuild& built, std::shared_ptr<const Geometry> moved, const RefitPolicy& policy) {
  for (std::uint32_t id : built.built.bvh.zero_area_triangles)
    if (!zero_area(*moved, id))
      return {nullptr, "triangle " + std::to_string(id) +
                           " was skipped at the build for zero area and has an area now: the tree has no place for it"};
  auto out = std::make_shared<MeshBuild>(built);
  out->geometry = std::move(moved);
  Bvh8& bvh = out->built.bvh;
  refit_bvh8(bvh, *out->geometry, bvh_thread_count(out->config));
  const double cost = bvh8_cost(bvh.nodes);
  const double ratio = built.build_cost > 0.0 ? cost / built.build_cost : 1.0;
  if (ratio > policy.max_cost_ratio)
    return {nullptr, "the SAH cost after a refit is " + std::to_string(ratio) + "x the build's, above " +
                         std::to_string(policy.max_cost_ratio)};
  out->built.stats.bounds = out->geometry->bounds();
  out->root_boxes.clear();
  const Bvh8Node& root = bvh.nodes.at(0);
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane)
    if (root.child[lane] != RTCL_CHILD_EMPTY) out->root_boxes.push_back(bvh8_lane_box(root, lane));
  return {std::move(out), ""};
}

std::shared_ptr<const DeviceBottoms> refit_bottoms(const Device& device, const DeviceBottoms& previous,
                                                   std::span<const std::shared_ptr<const MeshBuild>> previous_meshes,
                                                   std::span<const std::shared_ptr<const MeshBuild>> meshes,
                                                   const std::vector<bool>& refitted) {
  if (meshes.empty() || previous_meshes.size() != meshes.size() || refitted.size() != meshes.size()) return nullptr;
  // Each mesh's first node and triangle block, as upload_bottoms lays them.
  std::vector<std::size_t> first_node(meshes.size()), first_block(meshes.size());
  std::size_t nodes = 0, blocks = 0;
  for (std::size_t k = 0; k < meshes.size(); ++k) {
    const Bvh8 &now = meshes[k]->built.bvh, &before = previous_meshes[k]->built.bvh;
    if (refitted[k] ? now.nodes.size() != before.nodes.size() ||
                          now.blocks.triangles.size() != before.blocks.triangles.size() ||
                          now.blocks.spheres.size() != before.blocks.spheres.size()
                    : meshes[k] != previous_meshes[k])
      return nullptr;
    first_node[k] = nodes;
    first_block[k] = blocks;
    nodes += now.nodes.size();
    blocks += now.blocks.triangles.size();
  }
  return with_cl_errors([&] {
    const std::size_t node_bytes = previous.nodes.getInfo<CL_MEM_SIZE>();
    const std::size_t block_bytes = previous.triangles.getInfo<CL_MEM_SIZE>();
    if (node_bytes < nodes * sizeof(Bvh8Node) || block_bytes < blocks * sizeof(TriangleBlock))
      return std::shared_ptr<const DeviceBottoms>();
    auto out = std::make_shared<DeviceBottoms>(previous);
    out->nodes = device.allocate(node_bytes, "the scene's bottom levels' nodes");
    out->triangles = device.allocate(block_bytes, "the scene's bottom levels' triangle blocks");
    cl::CommandQueue& queue = device.queue();
    std::vector<cl::Event> copied(2), written;
    queue.enqueueCopyBuffer(previous.nodes, out->nodes, 0, 0, node_bytes, nullptr, &copied[0]);
    queue.enqueueCopyBuffer(previous.triangles, out->triangles, 0, 0, block_bytes, nullptr, &copied[1]);
    for (std::size_t k = 0; k < meshes.size(); ++k) {
      if (!refitted[k]) continue;
      const Bvh8& bvh = meshes[k]->built.bvh;
      written.emplace_back();
      queue.enqueueWriteBuffer(out->nodes, CL_FALSE, first_node[k] * sizeof(Bvh8Node),
                               bvh.nodes.size() * sizeof(Bvh8Node), bvh.nodes.data(), &copied, &written.back());
      if (bvh.blocks.triangles.empty()) continue;
      written.emplace_back();
      queue.enqueueWriteBuffer(out->triangles, CL_FALSE, first_block[k] * sizeof(TriangleBlock),
                               bvh.blocks.triangles.size() * sizeof(TriangleBlock), bvh.blocks.triangles.data(),
                               &copied, &written.back());
    }
    written.insert(written.end(), copied.begin(), copied.end());
    try {
      cl::Event::waitForEvents(written);
    } catch (...) {
      queue.finish();  // no write may still read the images once the caller lets them go
      throw;
    }
    return std::shared_ptr<const DeviceBottoms>(std::move(out));
  });
}

}  // namespace rtcl
