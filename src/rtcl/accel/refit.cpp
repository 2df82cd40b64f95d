#include "rtcl/accel/refit.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>
#include <utility>

#include "rtcl/accel/accel_state.hpp"
#include "rtcl/error.hpp"
#include "rtcl/parallel.hpp"

namespace rtcl {

namespace {

using Clock = std::chrono::steady_clock;

// Levels with fewer nodes than this are refitted together by one
// work-group (refit_levels), a barrier between levels, instead of one launch
// each: the top of a tree has levels of 1, 8, 64 ... nodes, where a
// launch costs more than the work.
constexpr std::uint32_t kLevelLaunchMin = 256;
// That work-group's size (at most the device's).
constexpr std::size_t kLevelsGroup = 64;
// Vertices or triangles per host thread in the checks (parallel.hpp).
constexpr std::size_t kCheckPartMin = 65536;

double elapsed_ms(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

double cost_of(double parts, double root_area) {
  return root_area > 0.0 ? (kRefitNodeCost * root_area + parts) / root_area : 1.0;
}

std::string unsupported(const std::string& name) {
  return "refit: structure " + name +
         " does not support refit (supported: bvh, bvh-ploc, bvh-packet); build it anew (make_accel, "
         "refit_or_rebuild)";
}

void check_policy(const RefitPolicy& policy, const char* call) {
  if (!(policy.max_cost_ratio >= 1.0))
    throw Error(std::string(call) + " policy.max_cost_ratio: " + std::to_string(policy.max_cost_ratio) +
                " must be >= 1 (+inf: never rebuild on cost)");
}

}  // namespace

double bvh8_cost(std::span<const Bvh8Node> nodes) {
  if (nodes.empty()) return 0.0;
  Aabb root;
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane)
    if (nodes[0].child[lane] != RTCL_CHILD_EMPTY) root.grow(bvh8_lane_box(nodes[0], lane));
  double parts = 0.0;
  for (const Bvh8Node& node : nodes)
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
      const rtcl_i32 c = node.child[lane];
      if (c == RTCL_CHILD_EMPTY) continue;
      parts += (c >= 0 ? kRefitNodeCost : 1.0f) * bvh8_lane_box(node, lane).area();
    }
  return cost_of(parts, root.area());
}

// ---- The shape ---------------------------------------------------------------

Bvh8Refit::Bvh8Refit(const Bvh8& bvh, const Geometry& geometry)
    : vertex_count_(geometry.vertices.size()),
      triangle_count_(geometry.triangles.size()),
      node_count_(bvh.nodes.size()),
      lane_count_(bvh.blocks.triangles.size() * RTCL_BLOCK_WIDTH),
      spheres_(geometry.spheres),
      zero_area_(bvh.zero_area_triangles) {
  // Depth of every node, from the root down (a node's children are
  // reached from it only: the flatten checked the tree).
  std::vector<std::uint32_t> depth(node_count_, 0);
  std::vector<std::uint32_t> count_at;  // nodes per depth
  std::vector<std::uint32_t> todo{0};
  while (!todo.empty()) {
    const std::uint32_t n = todo.back();
    todo.pop_back();
    if (depth[n] >= count_at.size()) count_at.resize(depth[n] + 1, 0);
    ++count_at[depth[n]];
    for (const rtcl_i32 c : bvh.nodes[n].child)
      if (c >= 0) {
        depth[static_cast<std::size_t>(c)] = depth[n] + 1;
        todo.push_back(static_cast<std::uint32_t>(c));
      }
  }
  // Levels deepest first.
  const auto levels = static_cast<std::uint32_t>(count_at.size());
  level_begin_.assign(levels + 1, 0);
  for (std::uint32_t l = 0; l < levels; ++l) level_begin_[l + 1] = level_begin_[l] + count_at[levels - 1 - l];
  if (level_begin_[levels] != node_count_) throw Error("internal: refit: the tree does not reach every node");
  std::vector<std::uint32_t> next(level_begin_.begin(), level_begin_.end() - 1);
  order_.resize(node_count_);
  for (std::uint32_t n = 0; n < node_count_; ++n) order_[next[levels - 1 - depth[n]]++] = n;
  build_cost_ = cost_ = bvh8_cost(bvh.nodes);
}

Bvh8Refit::Bvh8Refit(Bvh8Refit&&) noexcept = default;
Bvh8Refit::~Bvh8Refit() = default;

// ---- The device side ---------------------------------------------------------

struct Bvh8Refit::DeviceState {
  // One launch: refit_nodes over one level, or refit_levels over several.
  struct Run {
    bool grouped;
    std::uint32_t first_level, end_level;
  };
  cl::Buffer vertices, lane_vertices, order, level_begin, cost_parts;
  cl::Kernel lane_table, lanes, nodes, levels;
  std::vector<Run> runs;
  std::size_t levels_group = kLevelsGroup;
  std::vector<float> cost_parts_host;
  // The triangles lane_vertices was made from (empty: not made yet).
  std::vector<glm::uvec3> triangles;
};

Bvh8Refit::DeviceState& Bvh8Refit::device_state(const Device& device) {
  if (device_) return *device_;
  auto st = std::make_unique<DeviceState>();
  with_cl_errors([&] {
    cl::Program program = device.program("accel/refit.cl", {});
    st->lane_table = cl::Kernel(program, "refit_lane_vertices");
    st->lanes = cl::Kernel(program, "refit_triangle_lanes");
    st->nodes = cl::Kernel(program, "refit_nodes");
    st->levels = cl::Kernel(program, "refit_levels");
    st->levels_group = std::min(kLevelsGroup, st->levels.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(device.device()));
  });
  // Buffers of at least one element: OpenCL has no empty buffer.
  const auto bytes = [](std::size_t n, std::size_t each) { return std::max<std::size_t>(n, 1) * each; };
  st->vertices = device.allocate(bytes(vertex_count_, sizeof(glm::vec3)), "refit vertices", CL_MEM_READ_ONLY);
  st->lane_vertices = device.allocate(bytes(lane_count_, 3 * sizeof(std::uint32_t)), "refit lane vertices");
  st->order = device.upload(order_.data(), order_.size() * sizeof(std::uint32_t), "refit node order");
  st->level_begin = device.upload(level_begin_.data(), level_begin_.size() * sizeof(std::uint32_t), "refit levels");
  st->cost_parts = device.allocate(node_count_ * sizeof(float), "refit costs");
  st->cost_parts_host.resize(node_count_);
  const auto levels = static_cast<std::uint32_t>(level_begin_.size() - 1);
  for (std::uint32_t l = 0; l < levels; ++l) {
    const bool small = level_begin_[l + 1] - level_begin_[l] < kLevelLaunchMin;
    if (small && !st->runs.empty() && st->runs.back().grouped)
      st->runs.back().end_level = l + 1;
    else
      st->runs.push_back({small, l, l + 1});
  }
  device_ = std::move(st);
  order_ = {};  // on the device now
  return *device_;
}

// ---- One refit ---------------------------------------------------------------

void Bvh8Refit::check(const std::string& name, const Geometry& geometry) const {
  const std::string at = name + " refit of \"" + geometry.source + "\": geometry.";
  const auto count_error = [&](const char* field, std::size_t got, std::size_t built, const char* what) {
    return Error(at + field + " holds " + std::to_string(got) + " " + what + ", the structure was built over " +
                 std::to_string(built) + " (a refit keeps the mesh; build anew for another)");
  };
  if (geometry.vertices.size() != vertex_count_)
    throw count_error("vertices", geometry.vertices.size(), vertex_count_, "vertices");
  if (geometry.triangles.size() != triangle_count_)
    throw count_error("triangles", geometry.triangles.size(), triangle_count_, "triangles");
  if (geometry.spheres.size() != spheres_.size())
    throw count_error("spheres", geometry.spheres.size(), spheres_.size(), "spheres");
  for (std::size_t i = 0; i < spheres_.size(); ++i) {
    const Sphere &s = geometry.spheres[i], &b = spheres_[i];
    if (s.center != b.center || s.radius != b.radius)
      throw Error(at + "spheres[" + std::to_string(i) +
                  "] differs from the build's (a refit moves triangles only; build anew to move spheres)");
  }
  // A pass that the compiler vectorises (a float is NaN or infinite when
  // its exponent bits are all ones), then the first bad vertex's index.
  const auto infinite = [](float f) { return (std::bit_cast<std::uint32_t>(f) & 0x7f800000u) == 0x7f800000u; };
  const std::size_t vertices = geometry.vertices.size();
  for_each_part(vertices, part_count(vertices, 0, kCheckPartMin), [&](unsigned, std::size_t begin, std::size_t end) {
    bool bad = false;
    for (std::size_t i = begin; i < end; ++i) {
      const glm::vec3& v = geometry.vertices[i];
      bad |= infinite(v.x) | infinite(v.y) | infinite(v.z);
    }
    if (!bad) return;
    for (std::size_t i = begin; i < end; ++i) {
      const glm::vec3& v = geometry.vertices[i];
      if (infinite(v.x) || infinite(v.y) || infinite(v.z))
        throw Error(at + "vertices[" + std::to_string(i) + "] is not finite");
    }
  });
}

bool Bvh8Refit::same_triangles(const Geometry& geometry) const {
  const std::vector<glm::uvec3>& known = device_->triangles;
  if (known.size() != geometry.triangles.size() || known.empty()) return false;
  std::atomic<bool> same{true};
  const std::size_t n = known.size();
  for_each_part(n, part_count(n, 0, kCheckPartMin), [&](unsigned, std::size_t begin, std::size_t end) {
    if (std::memcmp(known.data() + begin, geometry.triangles.data() + begin, (end - begin) * sizeof(glm::uvec3)))
      same.store(false, std::memory_order_relaxed);
  });
  return same.load();
}

void Bvh8Refit::check_indices(const std::string& name, const Geometry& geometry) const {
  const std::size_t vertices = geometry.vertices.size(), triangles = geometry.triangles.size();
  for_each_part(triangles, part_count(triangles, 0, kCheckPartMin), [&](unsigned, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const glm::uvec3& t = geometry.triangles[i];
      if (t.x >= vertices || t.y >= vertices || t.z >= vertices)
        throw Error(name + " refit of \"" + geometry.source + "\": geometry.triangles[" + std::to_string(i) +
                    "] refers to a vertex beyond the " + std::to_string(vertices) + " vertices");
    }
  });
}

RefitStats Bvh8Refit::run(const Accel& accel, const cl::Buffer& nodes, const cl::Buffer& triangle_blocks,
                          const Geometry& geometry, const RefitPolicy& policy, Aabb* bounds) {
  static_assert(sizeof(glm::vec3) == 3 * sizeof(float) && sizeof(glm::uvec3) == 3 * sizeof(std::uint32_t),
                "vertices and triangles are uploaded as packed arrays");
  check(accel.name(), geometry);
  const Device& device = accel.device();
  DeviceState& st = device_state(device);  // allocations first: nothing changed yet when they fail
  // New triangles (or the first refit): their lane table is made again.
  const bool new_triangles = lane_count_ > 0 && !same_triangles(geometry);
  if (new_triangles || lane_count_ == 0) check_indices(accel.name(), geometry);
  RefitStats stats;
  stats.build_cost = build_cost_;
  stats.cost = cost_;
  for (std::uint32_t id : zero_area_)
    if (!zero_area(geometry, id)) {
      stats.refused = stats.needs_rebuild = true;
      stats.reason = "triangle " + std::to_string(id) +
                     " was skipped at the build for zero area and has an area now: the tree has no place for it";
      return stats;
    }
  std::vector<glm::uvec3> triangles_now = new_triangles ? geometry.triangles : std::vector<glm::uvec3>{};
  cl::Buffer indices;
  if (new_triangles)
    indices = device.allocate(triangle_count_ * sizeof(glm::uvec3), "refit indices", CL_MEM_READ_ONLY);
  Bvh8Node root{};
  cl::CommandQueue& queue = device.queue();
  // From the first kernel on the buffers change in place: an OpenCL error
  // past that point (a lost device) leaves the structure undefined.
  try {
    with_cl_errors([&] {
      // After every command already queued (traces in flight on an
      // out-of-order queue read these buffers).
      cl::Event before;
      queue.enqueueBarrierWithWaitList(nullptr, &before);
      std::vector<cl::Event> last{before};
      if (lane_count_ > 0) {
        const std::vector<cl::Event> wait{before};
        cl::Event vertices_done;
        queue.enqueueWriteBuffer(st.vertices, CL_FALSE, 0, vertex_count_ * sizeof(glm::vec3),
                                 geometry.vertices.data(), &wait, &vertices_done);
        last = {vertices_done};
        if (new_triangles) {
          cl::Event indices_done;
          queue.enqueueWriteBuffer(indices, CL_FALSE, 0, triangle_count_ * sizeof(glm::uvec3),
                                   geometry.triangles.data(), &wait, &indices_done);
          st.lane_table.setArg(0, triangle_blocks);
          st.lane_table.setArg(1, static_cast<cl_uint>(lane_count_));
          st.lane_table.setArg(2, indices);
          st.lane_table.setArg(3, st.lane_vertices);
          last.push_back(detail::AccelAccess::launch(accel, st.lane_table, lane_count_, {indices_done}));
        }
        st.lanes.setArg(0, triangle_blocks);
        st.lanes.setArg(1, static_cast<cl_uint>(lane_count_));
        st.lanes.setArg(2, st.lane_vertices);
        st.lanes.setArg(3, st.vertices);
        last = {detail::AccelAccess::launch(accel, st.lanes, lane_count_, last)};
      }
      for (const DeviceState::Run& run : st.runs) {
        cl::Event done;
        if (run.grouped) {
          st.levels.setArg(0, nodes);
          st.levels.setArg(1, triangle_blocks);
          st.levels.setArg(2, st.order);
          st.levels.setArg(3, st.level_begin);
          st.levels.setArg(4, static_cast<cl_uint>(run.first_level));
          st.levels.setArg(5, static_cast<cl_uint>(run.end_level));
          st.levels.setArg(6, kRefitNodeCost);
          st.levels.setArg(7, st.cost_parts);
          queue.enqueueNDRangeKernel(st.levels, cl::NullRange, cl::NDRange(st.levels_group),
                                     cl::NDRange(st.levels_group), &last, &done);
        } else {
          const std::uint32_t first = level_begin_[run.first_level];
          const std::uint32_t count = level_begin_[run.first_level + 1] - first;
          st.nodes.setArg(0, nodes);
          st.nodes.setArg(1, triangle_blocks);
          st.nodes.setArg(2, st.order);
          st.nodes.setArg(3, static_cast<cl_uint>(first));
          st.nodes.setArg(4, static_cast<cl_uint>(count));
          st.nodes.setArg(5, kRefitNodeCost);
          st.nodes.setArg(6, st.cost_parts);
          done = detail::AccelAccess::launch(accel, st.nodes, count, last);
        }
        last = {done};
      }
      cl::Event costs_read, root_read;
      queue.enqueueReadBuffer(st.cost_parts, CL_FALSE, 0, node_count_ * sizeof(float), st.cost_parts_host.data(),
                              &last, &costs_read);
      queue.enqueueReadBuffer(nodes, CL_FALSE, 0, sizeof(Bvh8Node), &root, &last, &root_read);
      cl::Event::waitForEvents({costs_read, root_read});
    });
  } catch (...) {
    device.queue().finish();  // no command may still read the caller's arrays
    if (new_triangles) st.triangles.clear();  // the lane table may be half made
    throw;
  }
  if (new_triangles) st.triangles = std::move(triangles_now);
  double parts = 0.0;
  for (float part : st.cost_parts_host) parts += part;
  Aabb root_box;
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane)
    if (root.child[lane] != RTCL_CHILD_EMPTY) root_box.grow(bvh8_lane_box(root, lane));
  cost_ = cost_of(parts, root_box.area());
  stats.cost = cost_;
  *bounds = root_box;
  if (stats.cost_ratio() > policy.max_cost_ratio) {
    stats.needs_rebuild = true;
    stats.reason = "the SAH cost is " + std::to_string(stats.cost_ratio()) + "x the build's, above " +
                   std::to_string(policy.max_cost_ratio);
  }
  return stats;
}

// ---- The public calls --------------------------------------------------------

RefitStats Accel::refit(const Geometry& geometry, const RefitPolicy& policy) {
  const auto start = Clock::now();
  if (!refittable()) throw Error(unsupported(name_));
  check_policy(policy, ("refit of " + name_).c_str());
  std::lock_guard lock(state_->mutex);
  Aabb bounds;
  RefitStats stats = refit_structure(geometry, policy, &bounds);
  if (!stats.refused) {
    stats_.bounds = bounds;
    state_->sort.reset();  // its origin grid spans the old box
  }
  stats.refit_ms = elapsed_ms(start);
  return stats;
}

RefitStats Accel::refit_structure(const Geometry&, const RefitPolicy&, Aabb*) { throw Error(unsupported(name_)); }

RefitStats refit_or_rebuild(std::unique_ptr<Accel>& accel, std::string_view name, const Geometry& geometry,
                            const AccelConfig& config, const RefitPolicy& policy) {
  const auto start = Clock::now();
  if (!accel) throw Error("refit_or_rebuild: accel is null");
  check_policy(policy, "refit_or_rebuild");
  const std::string structure = parse_accel_spec(name, "refit_or_rebuild name \"" + std::string(name) + "\"").name;
  if (structure != accel->name())
    throw Error("refit_or_rebuild name \"" + std::string(name) + "\": the structure is a " + accel->name());
  RefitStats stats;
  if (accel->supports_refit()) {
    stats = accel->refit(geometry, policy);
    if (!stats.needs_rebuild) return stats;
  } else {
    stats.reason = "structure " + accel->name() + " does not support refit";
  }
  accel = make_accel(accel->device(), name, geometry, config);
  stats.rebuilt = true;
  stats.needs_rebuild = false;
  stats.refit_ms = elapsed_ms(start);
  return stats;
}

}  // namespace rtcl
