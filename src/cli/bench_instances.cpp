#include "bench_instances.hpp"

#include <vector>

#include "bench/support/forest.hpp"
#include "bench/support/ray_sets.hpp"
#include "bench/support/timing.hpp"
#include "bench_scenes.hpp"
#include "rtcl/error.hpp"
#include "rtcl/opencl.hpp"
#include "rtcl/scene.hpp"
#ifdef RTCL_HAVE_EMBREE
#include "bench/support/embree_instances.hpp"
#endif

namespace rtcl::cli {

BenchInstances bench_instances(const Device& device, const BenchOptions& options, const std::string& scenes_dir,
                               unsigned embree_threads) {
  BenchInstances out;
  const LoadedBenchScene mesh = load_bench_scene(parse_bench_scene("bunny", scenes_dir));
  out.mesh = mesh.spec.text;
  out.instances = static_cast<std::size_t>(options.instances);
  const std::vector<Transform> placed = bench::forest_placements(out.instances, mesh.geometry.bounds(), 2);

  Scene scene(device);
  const MeshId id = scene.add_mesh(mesh.geometry);
  std::vector<InstanceId> ids;
  ids.reserve(placed.size());
  for (const Transform& t : placed) ids.push_back(scene.add_instance(id, t));
  out.bottom_commit_ms = scene.commit().build_ms;
  out.commit_ms = bench::top_level_commit_ms(scene, ids, placed, options.repeat + 1);
  out.commit_ms.erase(out.commit_ms.begin());  // the warm-up
  out.device_bytes = scene.stats().device_bytes;

  const std::vector<Ray> rays =
      bench::primary_rays(bench::forest_camera(out.instances, mesh.geometry.bounds()), options.size, options.size);
  out.ray_count = rays.size();
  cl::Buffer ray_buffer = device.upload(rays.data(), rays.size() * sizeof(Ray), "benchmark rays");
  cl::Buffer hit_buffer = device.allocate(rays.size() * sizeof(Hit), "benchmark hits", CL_MEM_WRITE_ONLY);
  const auto trace = [&] {
    const auto start = bench::Clock::now();
    with_cl_errors([&] { scene.trace(Query::closest, ray_buffer, hit_buffer, rays.size()).wait(); });
    return bench::ms_since(start);
  };
  trace();  // the warm-up: the program's first launch

#ifdef RTCL_HAVE_EMBREE
  if (embree_threads > 0) {
    bench::EmbreeInstances embree(mesh.geometry, embree_threads);
    out.embree_threads = embree_threads;
    out.embree_child_ms = embree.child_ms();
    embree.place(placed);  // the warm-up
    for (int r = 0; r < options.repeat; ++r) {
      auto [setup, commit] = embree.place(placed);
      out.embree_setup_ms.push_back(setup);
      out.embree_commit_ms.push_back(commit);
    }
    std::vector<bench::InstanceHit> answers;
    embree.trace(rays, &answers);  // the warm-up
    for (int r = 0; r < options.repeat; ++r) {
      out.trace_ms.push_back(trace());
      out.embree_trace_ms.push_back(embree.trace(rays));
    }
    std::vector<std::uint32_t> instance_ids(rays.size());
    const std::vector<Hit> hits = scene.intersect(rays, instance_ids);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const bool hit = hits[i].prim >= 0;
      out.agreeing += hit == (answers[i].prim >= 0) &&
                      (!hit || (answers[i].instance == instance_ids[i] && answers[i].prim == hits[i].prim));
    }
    return out;
  }
#else
  (void)embree_threads;
#endif
  for (int r = 0; r < options.repeat; ++r) out.trace_ms.push_back(trace());
  return out;
}

}  // namespace rtcl::cli
