// rtcl::Scene (rtcl/scene.hpp): pending edits, commit() and the queries of
// the committed state. A commit builds the bottom levels of new and
// updated meshes (MeshBuild), then either the single-level path (one
// static identity instance: its mesh's own structure answers) or a
// TwoLevel (src/rtcl/scene/two_level.hpp), and publishes them as one
// immutable Committed snapshot; queries take the snapshot that is current
// when they start.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <string>
#include <string_view>

#include "rtcl/accel/accel_state.hpp"
#include "rtcl/accel/refit.hpp"
#include "rtcl/error.hpp"
#include "rtcl/query/host_batches.hpp"
#include "rtcl/scene.hpp"
#include "rtcl/scene/mesh_refit.hpp"
#include "rtcl/scene/two_level.hpp"

namespace rtcl {

namespace {

struct MeshEntry {
  std::shared_ptr<const Geometry> geometry;
  std::string structure;  // the structure's name ("bvh", "bvh-ploc", "bvh-packet")
  AccelOptions options;   // resolved (every declared option)
  BvhConfig config;
  std::optional<RefitPolicy> refit;           // MeshOptions::refit
  std::shared_ptr<const MeshBuild> built;     // null: to build at the next commit
  std::shared_ptr<const MeshBuild> previous;  // the build that update_vertices replaced (same triangles)
  std::size_t instances = 0;                  // pending instances that use it
};

// What queries see: one commit's structures, never changed once published.
struct Committed {
  // The single-level path: one static instance with the identity transform.
  std::shared_ptr<const MeshBuild> single_mesh;
  std::shared_ptr<const Accel> single;
  std::uint32_t single_user_id = 0;
  // Otherwise the two levels (also for no instance at all: every ray misses).
  std::vector<std::shared_ptr<const MeshBuild>> bottom_meshes;  // in the order of two_level's bottoms
  std::shared_ptr<const TwoLevel> two_level;
  SceneStats stats;
};

std::string mesh_name(std::uint32_t id, const Geometry& geometry) {
  return "mesh " + std::to_string(id) + " (" + geometry.source + ")";
}

bool is_identity(const Transform& t) { return t == Transform::identity(); }

const char* const kBottomLevelStructures = "bvh, bvh-ploc, bvh-packet";

std::shared_ptr<const MeshBuild> build_mesh(const MeshEntry& entry) {
  auto build = std::make_shared<MeshBuild>();
  build->geometry = entry.geometry;
  build->structure = entry.structure;
  build->config = entry.config;
  build->built = build_bvh(*entry.geometry, entry.config);
  build->build_cost = bvh8_cost(build->built.bvh.nodes);
  const Bvh8Node& root = build->built.bvh.nodes.at(0);
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane)
    if (root.child[lane] != RTCL_CHILD_EMPTY) build->root_boxes.push_back(bvh8_lane_box(root, lane));
  return build;
}

void check_sizes(const char* call, std::size_t rays, std::size_t hits, std::size_t ids, std::size_t times) {
  const auto count = [](std::size_t n) { return std::to_string(n); };
  if (hits != rays) throw Error(std::string(call) + ": hits holds " + count(hits) + " records for " + count(rays) + " rays");
  if (ids != 0 && ids != rays)
    throw Error(std::string(call) + ": instance_ids holds " + count(ids) + " values for " + count(rays) + " rays");
  if (times != 0 && times != rays)
    throw Error(std::string(call) + ": times holds " + count(times) + " values for " + count(rays) + " rays");
}

}  // namespace

struct Scene::State {
  Device device;
  SceneConfig config;

  // Pending edits, and the commit that consumes them.
  std::mutex edit_mutex;
  std::map<std::uint32_t, MeshEntry> meshes;
  std::uint32_t next_mesh = 0;
  std::vector<std::optional<Instance>> instances;  // by InstanceId; removed: empty
  std::size_t live_instances = 0;
  bool instances_changed = false;
  std::size_t bottom_levels_built = 0, bottom_levels_refitted = 0, top_levels_built = 0;
  // The commit's instances as the top level takes them: kept between
  // commits, so that a commit writes pages it has written before.
  std::vector<PlacedInstance> placed;

  // The published commit (the pointer alone is guarded).
  mutable std::mutex committed_mutex;
  std::shared_ptr<const Committed> committed;

  // Host-array queries of the two-level path: their staging, one call at a time.
  mutable std::mutex query_mutex;
  mutable std::vector<unsigned char> staging;
  // The single-level path's instance-id kernel (kernels/accel/instances.cl).
  mutable std::mutex ids_mutex;
  mutable std::optional<cl::Kernel> ids_kernel;

  State(const Device& d, const SceneConfig& c) : device(d), config(c) {}

  std::shared_ptr<const Committed> snapshot() const {
    std::lock_guard lock(committed_mutex);
    return committed;
  }

  MeshEntry& mesh_entry(MeshId id, std::string_view call) {
    auto found = meshes.find(id.value);
    if (found == meshes.end())
      throw Error(std::string(call) + ": mesh " + std::to_string(id.value) +
                  " does not exist (never added, or removed)");
    return found->second;
  }

  Instance& instance_entry(InstanceId id, std::string_view call) {
    if (id.value >= instances.size() || !instances[id.value])
      throw Error(std::string(call) + ": instance " + std::to_string(id.value) +
                  " does not exist (never added, or removed)");
    return *instances[id.value];
  }

  // Throws unless `instance` can be placed (its mesh exists, its transforms
  // are usable, its user id is not kNoInstance); who() names it (called on
  // an error only: a scene's edits run per frame).
  template <class Who>
  void check_instance(const Instance& instance, const Who& who) {
    if (!meshes.contains(instance.mesh.value)) mesh_entry(instance.mesh, who());  // throws its error
    std::string problem = instance.at_close ? motion_problem(instance.transform, *instance.at_close)
                                            : transform_problem(instance.transform);
    if (!problem.empty()) throw Error(who() + ": " + problem);
    if (instance.user_id && *instance.user_id == kNoInstance)
      throw Error(who() + ": user_id " + std::to_string(kNoInstance) + " is kNoInstance, which marks a miss");
  }

  cl::Kernel& ids_kernel_locked() const {
    if (!ids_kernel) {
      cl::Program program = device.program("accel/instances.cl", {"RTCL_QUERY_CLOSEST"});
      with_cl_errors([&] { ids_kernel = cl::Kernel(program, "instance_ids_of_hits"); });
    }
    return *ids_kernel;
  }
};

Scene::Scene(const Device& device, const SceneConfig& config) : state_(std::make_unique<State>(device, config)) {
  require_precision(device.info(), config.precision);
}

Scene::~Scene() = default;

const Device& Scene::device() const { return state_->device; }
Precision Scene::precision() const { return state_->config.precision; }

MeshId Scene::add_mesh(const Geometry& geometry, const MeshOptions& options) {
  State& st = *state_;
  const std::string call = "Scene::add_mesh structure \"" + options.structure + "\"";
  AccelSpec spec = parse_accel_spec(options.structure, call);
  if (spec.name != "bvh" && spec.name != "bvh-ploc" && spec.name != "bvh-packet")
    throw Error(call + ": " + spec.name + " cannot serve as a mesh's bottom level (supported: " +
                kBottomLevelStructures + ")");
  AccelOptions given = spec.options;
  for (const auto& [option, value] : options.options.values()) given.set(option, value);
  MeshEntry entry;
  entry.options = resolve_options(structure_spec(spec.name), given, call);
  entry.structure = spec.name;
  entry.config = bvh_config_from(entry.options);
  if (options.refit && !(options.refit->max_cost_ratio >= 1.0))
    throw Error("Scene::add_mesh refit.max_cost_ratio: " + std::to_string(options.refit->max_cost_ratio) +
                " must be >= 1 (+inf: never rebuild on cost)");
  entry.refit = options.refit;
  if (spec.name == "bvh-packet") entry.config.traversal = BvhTraversal::packet;
  try {
    validate(geometry);
  } catch (const Error& e) {
    throw Error("Scene::add_mesh: " + std::string(e.what()));
  }
  entry.geometry = std::make_shared<const Geometry>(geometry);
  std::lock_guard lock(st.edit_mutex);
  const std::uint32_t id = st.next_mesh;
  if (id == 0xffffffffu) throw Error("Scene::add_mesh: the scene has used every mesh id");
  st.meshes.emplace(id, std::move(entry));
  ++st.next_mesh;
  return MeshId{id};
}

void Scene::update_vertices(MeshId mesh, std::span<const float> xyz) {
  State& st = *state_;
  std::lock_guard lock(st.edit_mutex);
  MeshEntry& entry = st.mesh_entry(mesh, "Scene::update_vertices");
  const std::string who = "Scene::update_vertices " + mesh_name(mesh.value, *entry.geometry);
  const std::size_t vertices = entry.geometry->vertices.size();
  if (xyz.size() != 3 * vertices)
    throw Error(who + ": " + std::to_string(xyz.size()) + " coordinates for " + std::to_string(vertices) +
                " vertices (" + std::to_string(3 * vertices) + " expected)");
  auto moved = std::make_shared<Geometry>(*entry.geometry);
  for (std::size_t v = 0; v < vertices; ++v) moved->vertices[v] = {xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]};
  try {
    validate(*moved);
  } catch (const Error& e) {
    throw Error(who + ": " + e.what());
  }
  if (entry.built) entry.previous = entry.built;
  entry.built.reset();
  entry.geometry = std::move(moved);
}

void Scene::remove_mesh(MeshId mesh) {
  State& st = *state_;
  std::lock_guard lock(st.edit_mutex);
  MeshEntry& entry = st.mesh_entry(mesh, "Scene::remove_mesh");
  if (entry.instances > 0) {
    std::string users;
    std::size_t listed = 0;
    for (std::size_t i = 0; i < st.instances.size() && listed < 5; ++i)
      if (st.instances[i] && st.instances[i]->mesh == mesh) users += (listed++ ? ", " : "") + std::to_string(i);
    throw Error("Scene::remove_mesh " + mesh_name(mesh.value, *entry.geometry) + ": " +
                std::to_string(entry.instances) + " instance(s) still use it (" + users +
                (entry.instances > listed ? ", ..." : "") + "); remove them first");
  }
  st.meshes.erase(mesh.value);
}

InstanceId Scene::add_instance(const Instance& instance) {
  State& st = *state_;
  std::lock_guard lock(st.edit_mutex);
  const auto id = static_cast<std::uint32_t>(st.instances.size());
  st.check_instance(instance, [&] {
    return "Scene::add_instance (instance " + std::to_string(id) + " of mesh " + std::to_string(instance.mesh.value) +
           ")";
  });
  if (id == kNoInstance) throw Error("Scene::add_instance: the scene has used every instance id");
  st.instances.push_back(instance);
  ++st.meshes.at(instance.mesh.value).instances;
  ++st.live_instances;
  st.instances_changed = true;
  return InstanceId{id};
}

void Scene::set_instance(InstanceId id, const Instance& instance) {
  State& st = *state_;
  std::lock_guard lock(st.edit_mutex);
  Instance& current = st.instance_entry(id, "Scene::set_instance");
  st.check_instance(instance, [&] {
    return "Scene::set_instance instance " + std::to_string(id.value) + " (mesh " +
           std::to_string(instance.mesh.value) + ")";
  });
  --st.meshes.at(current.mesh.value).instances;
  ++st.meshes.at(instance.mesh.value).instances;
  current = instance;
  st.instances_changed = true;
}

void Scene::set_transform(InstanceId id, const Transform& transform) {
  State& st = *state_;
  std::lock_guard lock(st.edit_mutex);
  Instance& current = st.instance_entry(id, "Scene::set_transform");
  Instance changed = current;
  changed.transform = transform;
  changed.at_close.reset();
  st.check_instance(changed, [&] {
    return "Scene::set_transform instance " + std::to_string(id.value) + " (mesh " +
           std::to_string(changed.mesh.value) + ")";
  });
  current = changed;
  st.instances_changed = true;
}

void Scene::remove_instance(InstanceId id) {
  State& st = *state_;
  std::lock_guard lock(st.edit_mutex);
  Instance& current = st.instance_entry(id, "Scene::remove_instance");
  --st.meshes.at(current.mesh.value).instances;
  st.instances[id.value].reset();
  --st.live_instances;
  st.instances_changed = true;
}

Instance Scene::instance(InstanceId id) const {
  State& st = *state_;
  std::lock_guard lock(st.edit_mutex);
  return st.instance_entry(id, "Scene::instance");
}

CommitStats Scene::commit() {
  State& st = *state_;
  std::lock_guard lock(st.edit_mutex);
  const auto start = std::chrono::steady_clock::now();
  const std::shared_ptr<const Committed> previous = st.snapshot();
  CommitStats stats;

  // Bottom levels of new and updated meshes, kept aside until the commit
  // succeeds. A mesh whose vertices moved over the same triangles
  // (update_vertices; entry.previous is its last build) is refitted from
  // that build (src/rtcl/scene/mesh_refit.hpp) unless its policy asks for a
  // rebuild; refit_source holds the build each refit started from.
  std::map<std::uint32_t, std::shared_ptr<const MeshBuild>> builds;
  std::map<std::uint32_t, const MeshBuild*> refit_source;
  for (const auto& [id, entry] : st.meshes) {
    if (entry.built) {
      builds.emplace(id, entry.built);
      continue;
    }
    try {
      if (entry.previous && entry.refit) {
        MeshRefit refit = refit_mesh(*entry.previous, entry.geometry, *entry.refit);
        if (refit.build) {
          builds.emplace(id, std::move(refit.build));
          refit_source.emplace(id, entry.previous.get());
          ++stats.bottom_levels_refitted;
          continue;
        }
      }
      builds.emplace(id, build_mesh(entry));
    } catch (const Error& e) {
      throw Error("Scene::commit " + mesh_name(id, *entry.geometry) + ": " + e.what());
    }
    ++stats.bottom_levels_built;
  }

  auto next = std::make_shared<Committed>();
  std::vector<std::uint32_t> live;
  for (std::size_t i = 0; i < st.instances.size(); ++i)
    if (st.instances[i]) live.push_back(static_cast<std::uint32_t>(i));
  const auto user_id = [&](std::uint32_t i) { return st.instances[i]->user_id.value_or(i); };

  // The structures queries will see; an error names the commit (a mesh's
  // build error already does).
  try {
    if (live.size() == 1 && !st.instances[live[0]]->at_close && is_identity(st.instances[live[0]]->transform)) {
      const Instance& only = *st.instances[live[0]];
      next->single_mesh = builds.at(only.mesh.value);
      next->single_user_id = user_id(live[0]);
      if (previous && previous->single_mesh == next->single_mesh) {
        next->single = previous->single;
      } else {
        const MeshEntry& entry = st.meshes.at(only.mesh.value);
        AccelConfig config{st.config.precision, entry.options, st.config.scattered_sort};
        next->single = make_bvh_accel(st.device, next->single_mesh->built, *next->single_mesh->geometry, entry.config,
                                      entry.structure, config);
      }
      stats.top_level_built = false;
      next->stats.device_bytes = next->single->stats().device_bytes;
      next->stats.single_level = true;
    } else {
      std::map<std::uint32_t, std::uint32_t> bottom_of;
      const bool had_two_levels = previous && previous->two_level;
      std::vector<bool> refitted;  // bottom k is a refit of the previous commit's bottom k
      for (const auto& [id, build] : builds) {
        const std::size_t k = next->bottom_meshes.size();
        bottom_of[id] = static_cast<std::uint32_t>(k);
        next->bottom_meshes.push_back(build);
        const auto source = refit_source.find(id);
        refitted.push_back(had_two_levels && source != refit_source.end() && k < previous->bottom_meshes.size() &&
                           previous->bottom_meshes[k].get() == source->second);
      }
      const bool same_bottoms = had_two_levels && previous->bottom_meshes == next->bottom_meshes;
      if (same_bottoms && !st.instances_changed) {
        next->two_level = previous->two_level;
      } else {
        // The previous commit's bottom levels; else, where only refits
        // changed them, a device copy with the refitted meshes' ranges
        // written anew; else every mesh uploaded.
        std::shared_ptr<const DeviceBottoms> bottoms;
        if (same_bottoms)
          bottoms = previous->two_level->bottoms();
        else if (had_two_levels && !refit_source.empty())
          bottoms = refit_bottoms(st.device, *previous->two_level->bottoms(), previous->bottom_meshes,
                                  next->bottom_meshes, refitted);
        if (!bottoms) bottoms = std::make_shared<const DeviceBottoms>(upload_bottoms(st.device, next->bottom_meshes));
        std::vector<PlacedInstance>& placed = st.placed;
        placed.clear();
        placed.reserve(live.size());
        auto last = bottom_of.end();  // instances of one mesh come in runs: one map search per run
        for (std::uint32_t i : live) {
          const Instance& in = *st.instances[i];
          if (last == bottom_of.end() || last->first != in.mesh.value) last = bottom_of.find(in.mesh.value);
          placed.push_back({last->second, in.transform, in.at_close, user_id(i)});
        }
        next->two_level =
            std::make_shared<const TwoLevel>(st.device, st.config.precision, std::move(bottoms), next->bottom_meshes,
                                             placed, previous ? previous->two_level.get() : nullptr);
        stats.top_level_built = true;
      }
      next->stats.device_bytes = next->two_level->device_bytes();
    }
  } catch (const Error& e) {
    throw Error("Scene::commit: " + std::string(e.what()));
  }

  // Published: nothing below throws.
  for (auto& [id, entry] : st.meshes) {
    if (!entry.built) entry.previous.reset();
    entry.built = builds.at(id);
  }
  st.instances_changed = false;
  st.bottom_levels_built += stats.bottom_levels_built;
  st.bottom_levels_refitted += stats.bottom_levels_refitted;
  if (stats.top_level_built) ++st.top_levels_built;
  next->stats.meshes = st.meshes.size();
  next->stats.instances = live.size();
  next->stats.bottom_levels_built = st.bottom_levels_built;
  next->stats.bottom_levels_refitted = st.bottom_levels_refitted;
  next->stats.top_levels_built = st.top_levels_built;
  stats.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  {
    std::lock_guard publish(st.committed_mutex);
    st.committed = std::move(next);
  }
  return stats;
}

SceneStats Scene::stats() const {
  std::shared_ptr<const Committed> c = state_->snapshot();
  return c ? c->stats : SceneStats{};
}

void Scene::trace(Query query, const Rays& rays, std::span<Hit> hits, std::span<std::uint32_t> instance_ids,
                  std::span<const float> times, Coherence coherence) const {
  const State& st = *state_;
  const char* call = query == Query::closest ? "Scene::intersect" : "Scene::occluded";
  check_sizes(call, rays.size(), hits.size(), instance_ids.size(), times.size());
  if (rays.size() > 0 && !hits.data()) throw Error(std::string(call) + ": null hits array");
  const std::shared_ptr<const Committed> c = st.snapshot();
  if (!c) {
    std::fill(hits.begin(), hits.end(), Hit{INFINITY, 0.0f, 0.0f, -1});
    std::fill(instance_ids.begin(), instance_ids.end(), kNoInstance);
    return;
  }
  if (c->single) {
    c->single->trace(query, rays, hits, coherence);
    for (std::size_t i = 0; i < instance_ids.size(); ++i)
      instance_ids[i] = hits[i].prim >= 0 ? c->single_user_id : kNoInstance;
    return;
  }
  const Device& device = st.device;
  HostBatches batches(device, rays.size(), sizeof(Ray), sizeof(Hit));
  std::lock_guard lock(st.query_mutex);
  std::size_t next = 0;  // batches are enqueued in order of their first ray
  std::vector<cl::Event> reads;
  std::vector<cl::Buffer> keep;  // side buffers of batches in flight
  run_rays(
      batches, rays, st.staging,
      [&](const cl::Buffer& in, const cl::Buffer& out, std::size_t n, const std::vector<cl::Event>& wait) {
        const std::size_t first = next;
        next += n;
        cl::CommandQueue& queue = device.queue();
        std::vector<cl::Event> before = wait;
        cl::Buffer time_buffer, id_buffer;
        if (!times.empty()) {
          time_buffer = device.allocate(n * sizeof(float), "ray times batch", CL_MEM_READ_ONLY);
          cl::Event uploaded;
          queue.enqueueWriteBuffer(time_buffer, CL_FALSE, 0, n * sizeof(float), times.data() + first, nullptr,
                                   &uploaded);
          before.push_back(uploaded);
          keep.push_back(time_buffer);
        }
        if (!instance_ids.empty()) id_buffer = device.allocate(n * sizeof(cl_uint), "instance ids batch", CL_MEM_WRITE_ONLY);
        cl::Event done = c->two_level->trace(query, in, out, n, instance_ids.empty() ? nullptr : &id_buffer,
                                             times.empty() ? nullptr : &time_buffer, 1, 0, before);
        if (!instance_ids.empty()) {
          std::vector<cl::Event> after{done};
          cl::Event read;
          queue.enqueueReadBuffer(id_buffer, CL_FALSE, 0, n * sizeof(cl_uint), instance_ids.data() + first, &after,
                                  &read);
          reads.push_back(read);
          keep.push_back(id_buffer);
        }
        return done;
      },
      hits.data());
  with_cl_errors([&] {
    if (!reads.empty()) cl::Event::waitForEvents(reads);
  });
}

std::vector<Hit> Scene::intersect(const Rays& rays, std::span<std::uint32_t> instance_ids,
                                  std::span<const float> times) const {
  std::vector<Hit> hits(rays.size());
  trace(Query::closest, rays, hits, instance_ids, times);
  return hits;
}

std::vector<std::uint8_t> Scene::occluded(const Rays& rays, std::span<const float> times) const {
  std::vector<Hit> hits(rays.size());
  trace(Query::any, rays, hits, {}, times);
  std::vector<std::uint8_t> blocked(rays.size());
  for (std::size_t i = 0; i < hits.size(); ++i) blocked[i] = hits[i].prim >= 0 ? 1 : 0;
  return blocked;
}

cl::Event Scene::trace(Query query, const cl::Buffer& rays, const cl::Buffer& hits, std::size_t ray_count,
                       const SceneBuffers& extra, const std::vector<cl::Event>& wait, Coherence coherence) const {
  const State& st = *state_;
  return with_cl_errors([&] {
    const auto holds = [](const cl::Buffer& b) { return b() ? b.getInfo<CL_MEM_SIZE>() : std::size_t{0}; };
    if (ray_count > 0xffffffffu) throw Error("Scene::trace: ray_count " + std::to_string(ray_count) + " exceeds 2^32-1");
    if (holds(rays) < ray_count * sizeof(Ray) || holds(hits) < ray_count * sizeof(Hit))
      throw Error("Scene::trace: the ray or hit buffer holds fewer than " + std::to_string(ray_count) + " records");
    const cl::Buffer* ids = extra.instance_ids() ? &extra.instance_ids : nullptr;
    const cl::Buffer* times = extra.times() ? &extra.times : nullptr;
    if (ids && holds(*ids) < ray_count * sizeof(cl_uint))
      throw Error("Scene::trace: the instance_ids buffer holds fewer than " + std::to_string(ray_count) + " values");
    if (times && ray_count > 0) {
      const std::size_t need = (ray_count - 1) * std::size_t{extra.time_stride} + extra.time_offset + 1;
      if (holds(*times) / sizeof(float) < need)
        throw Error("Scene::trace: the times buffer holds " + std::to_string(holds(*times) / sizeof(float)) +
                    " floats, " + std::to_string(need) + " needed for " + std::to_string(ray_count) + " rays");
    }
    const std::shared_ptr<const Committed> c = st.snapshot();
    cl::CommandQueue& queue = st.device.queue();
    if (!c) {
      const Hit miss{INFINITY, 0.0f, 0.0f, -1};
      cl::Event filled;
      queue.enqueueFillBuffer(hits, miss, 0, ray_count * sizeof(Hit), &wait, &filled);
      if (!ids) return filled;
      std::vector<cl::Event> after{filled};
      cl::Event done;
      queue.enqueueFillBuffer(*ids, kNoInstance, 0, ray_count * sizeof(cl_uint), &after, &done);
      return done;
    }
    if (c->single) {
      cl::Event traced = c->single->trace(query, rays, hits, ray_count, wait, coherence);
      if (!ids) return traced;
      std::lock_guard lock(st.ids_mutex);
      cl::Kernel& k = st.ids_kernel_locked();
      k.setArg(0, hits);
      k.setArg(1, *ids);
      k.setArg(2, static_cast<cl_uint>(ray_count));
      k.setArg(3, static_cast<cl_uint>(c->single_user_id));
      return detail::launch_items(st.device, k, ray_count, {traced});
    }
    return c->two_level->trace(query, rays, hits, ray_count, ids, times, extra.time_stride, extra.time_offset, wait);
  });
}

}  // namespace rtcl
