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

// refit.cl's RTCL_REFIT_ROOT: the root's entry in up_.
constexpr std::uint32_t kRefitRoot = 0xffffffffu;
// Vertices or triangles per host thread in the checks (parallel.hpp).
constexpr std::size_t kCheckPartMin = 65536;
// Floats and triangle indices per host thread in a refit's scan: a pooled
// thread spins for its next job after its part (thread_pool.hpp), on a CPU
// device on a core that the refit's kernel then wants, so the scan takes a
// second thread only where that saves more than its spin costs.
constexpr std::size_t kScanPartMin = std::size_t{1} << 22;

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

// ---- The host refit ----------------------------------------------------------

namespace {

// Triangle blocks and nodes per host thread in refit_bvh8 (parallel.hpp).
constexpr std::size_t kHostBlocksPerPart = 4096;
constexpr std::size_t kHostNodesPerPart = 1024;

// Lane `lane` of `node` set to the box.
void set_lane(Bvh8Node& node, int lane, const glm::vec3& lower, const glm::vec3& upper) {
  for (int axis = 0; axis < 3; ++axis) {
    node.bounds[axis][lane] = lower[axis];
    node.bounds[3 + axis][lane] = upper[axis];
  }
}

// Node n's lanes from its children's lanes and blocks, as refit.cl makes
// them.
void refit_host_node(std::span<Bvh8Node> nodes, const PrimitiveBlocks& blocks, std::size_t n) {
  Bvh8Node& node = nodes[n];
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
    const rtcl_i32 c = node.child[lane];
    if (c == RTCL_CHILD_EMPTY) continue;
    glm::vec3 lower(INFINITY), upper(-INFINITY);
    if (c >= 0) {
      const Bvh8Node& child = nodes[static_cast<std::size_t>(c)];
      for (int axis = 0; axis < 3; ++axis)
        for (int k = 0; k < RTCL_BLOCK_WIDTH; ++k) {
          lower[axis] = std::min(lower[axis], child.bounds[axis][k]);
          upper[axis] = std::max(upper[axis], child.bounds[3 + axis][k]);
        }
    } else if ((~c & 1) == 0) {
      const TriangleBlock& block = blocks.triangles[static_cast<std::uint32_t>(~c) >> 1];
      for (int k = 0; k < RTCL_BLOCK_WIDTH; ++k) {
        if (block.prim[k] < 0) continue;
        for (int corner = 0; corner < 3; ++corner)
          for (int axis = 0; axis < 3; ++axis) {
            lower[axis] = std::min(lower[axis], block.v[corner][axis][k]);
            upper[axis] = std::max(upper[axis], block.v[corner][axis][k]);
          }
      }
    } else {
      continue;  // a sphere block: as built
    }
    set_lane(node, lane, lower, upper);
  }
}

}  // namespace

void refit_bvh8(Bvh8& bvh, const Geometry& geometry, unsigned threads) {
  // 1. The triangle blocks' used lanes from the vertices.
  auto& blocks = bvh.blocks.triangles;
  for_each_part(blocks.size(), part_count(blocks.size(), threads, kHostBlocksPerPart),
                [&](unsigned, std::size_t begin, std::size_t end) {
                  for (std::size_t b = begin; b < end; ++b) {
                    TriangleBlock& block = blocks[b];
                    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
                      if (block.prim[lane] < 0) continue;
                      const glm::uvec3 t = geometry.triangles[static_cast<std::size_t>(block.prim[lane])];
                      const glm::vec3 corners[3] = {geometry.vertices[t.x], geometry.vertices[t.y],
                                                    geometry.vertices[t.z]};
                      for (int corner = 0; corner < 3; ++corner)
                        for (int axis = 0; axis < 3; ++axis) block.v[corner][axis][lane] = corners[corner][axis];
                    }
                  }
                });
  // 2. The nodes, deepest level first. The flatten numbers a node's
  // children after it (bvh_flatten.cpp), so one pass in index order gives
  // every node's depth.
  const std::size_t count = bvh.nodes.size();
  std::vector<std::uint32_t> depth(count, 0), at_depth;
  for (std::size_t n = 0; n < count; ++n) {
    if (depth[n] >= at_depth.size()) at_depth.resize(depth[n] + 1, 0);
    ++at_depth[depth[n]];
    for (const rtcl_i32 c : bvh.nodes[n].child)
      if (c >= 0) {
        if (static_cast<std::size_t>(c) <= n || static_cast<std::size_t>(c) >= count)
          throw Error("internal: refit: node " + std::to_string(n) + " has child " + std::to_string(c) +
                      " that does not follow it");
        depth[static_cast<std::size_t>(c)] = depth[n] + 1;
      }
  }
  std::vector<std::uint32_t> begin(at_depth.size() + 1, 0), order(count);
  for (std::size_t d = 0; d < at_depth.size(); ++d) begin[d + 1] = begin[d] + at_depth[d];
  std::vector<std::uint32_t> next(begin.begin(), begin.end() - 1);
  for (std::size_t n = 0; n < count; ++n) order[next[depth[n]]++] = static_cast<std::uint32_t>(n);
  const std::span<Bvh8Node> nodes(bvh.nodes);
  for (std::size_t d = at_depth.size(); d-- > 0;) {
    const std::size_t first = begin[d], level = at_depth[d];
    for_each_part(level, part_count(level, threads, kHostNodesPerPart), [&](unsigned, std::size_t b, std::size_t e) {
      for (std::size_t i = first + b; i < first + e; ++i) refit_host_node(nodes, bvh.blocks, order[i]);
    });
  }
}

// ---- The shape ---------------------------------------------------------------

Bvh8Refit::Bvh8Refit(const Bvh8& bvh, const Geometry& geometry)
    : vertex_count_(geometry.vertices.size()),
      triangle_count_(geometry.triangles.size()),
      node_count_(bvh.nodes.size()),
      lane_count_(bvh.blocks.triangles.size() * RTCL_BLOCK_WIDTH),
      spheres_(geometry.spheres),
      zero_area_(bvh.zero_area_triangles) {
  // Every node's place in its parent (parent * 8 + lane), the lanes each
  // node waits for (inner nodes and triangle blocks), the nodes with
  // triangle blocks and the nodes that wait for none. Each node and block
  // must be reached once (the flatten checked the tree; a broken one is an
  // internal error).
  const std::size_t blocks = bvh.blocks.triangles.size();
  if (node_count_ >= (std::size_t{1} << 29) || blocks >= (std::size_t{1} << 32))
    throw Error("refit: the tree has more nodes or blocks than its refit indexes (2^29 nodes)");
  up_.assign(node_count_, kRefitRoot);
  arrivals_.assign(node_count_, 0);
  std::vector<bool> block_reached(blocks, false);
  std::size_t reached = 1, blocks_reached = 0;
  for (std::size_t n = 0; n < node_count_; ++n) {
    bool has_blocks = false;
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
      const rtcl_i32 c = bvh.nodes[n].child[lane];
      const auto place = static_cast<std::uint32_t>(n * RTCL_BLOCK_WIDTH + static_cast<std::size_t>(lane));
      bool fresh = false;
      if (c >= 0 && static_cast<std::size_t>(c) < node_count_ && c != 0) {
        std::uint32_t& slot = up_[static_cast<std::size_t>(c)];
        fresh = slot == kRefitRoot;
        slot = place;
        ++reached;
      } else if (c < 0 && c != RTCL_CHILD_EMPTY && (~c & 1) == 0 &&
                 (static_cast<std::uint32_t>(~c) >> 1) < blocks) {
        const std::size_t b = static_cast<std::uint32_t>(~c) >> 1;
        fresh = !block_reached[b];
        block_reached[b] = true;
        ++blocks_reached;
        has_blocks = true;
      } else if (c == RTCL_CHILD_EMPTY || (c < 0 && (~c & 1) == 1)) {
        continue;  // empty, or a sphere block: as built
      }
      if (!fresh)
        throw Error("internal: refit: node " + std::to_string(n) + " lane " + std::to_string(lane) +
                    " refers to a child that does not exist or has another parent");
      ++arrivals_[n];
    }
    if (has_blocks) block_nodes_.push_back(static_cast<std::uint32_t>(n));
  }
  if (reached != node_count_ || blocks_reached != blocks)
    throw Error("internal: refit: the tree does not reach every node and block");
  for (std::size_t n = 0; n < node_count_; ++n)
    if (arrivals_[n] == 0) start_nodes_.push_back(static_cast<std::uint32_t>(n));
  build_cost_ = cost_ = bvh8_cost(bvh.nodes);
}

Bvh8Refit::Bvh8Refit(Bvh8Refit&&) noexcept = default;
Bvh8Refit::~Bvh8Refit() = default;

// ---- The device side ---------------------------------------------------------

struct Bvh8Refit::DeviceState {
  cl::Buffer vertices, lane_vertices, up, arrivals, counters, block_nodes, start_nodes, cost_parts;
  cl::Kernel lane_table, bottom_up;
  std::vector<float> cost_parts_host;
  // The counters are all 0 (a refit that failed on the device may leave
  // some counted: the next one clears them first).
  bool counters_clear = true;
  // The triangles lane_vertices was made from (empty: not made yet).
  std::vector<glm::uvec3> triangles;
};

Bvh8Refit::DeviceState& Bvh8Refit::device_state(const Device& device) {
  if (device_) return *device_;
  auto st = std::make_unique<DeviceState>();
  with_cl_errors([&] {
    cl::Program program = device.program("accel/refit.cl", {});
    st->lane_table = cl::Kernel(program, "refit_lane_vertices");
    st->bottom_up = cl::Kernel(program, "refit_bottom_up");
  });
  // Buffers of at least one element: OpenCL has no empty buffer.
  const auto bytes = [](std::size_t n, std::size_t each) { return std::max<std::size_t>(n, 1) * each; };
  st->vertices = device.allocate(bytes(vertex_count_, sizeof(glm::vec3)), "refit vertices", CL_MEM_READ_ONLY);
  st->lane_vertices = device.allocate(bytes(lane_count_, 3 * sizeof(std::uint32_t)), "refit lane vertices");
  const auto upload = [&](const std::vector<std::uint32_t>& v, const char* what) {
    const std::uint32_t none = 0;
    return v.empty() ? device.upload(&none, sizeof none, what)
                     : device.upload(v.data(), v.size() * sizeof(std::uint32_t), what);
  };
  st->up = upload(up_, "refit parents of nodes");
  st->arrivals = upload(arrivals_, "refit lanes per node");
  st->block_nodes = upload(block_nodes_, "refit block nodes");
  st->start_nodes = upload(start_nodes_, "refit start nodes");
  st->counters = upload(std::vector<std::uint32_t>(node_count_, 0), "refit counters");
  st->cost_parts = device.allocate(node_count_ * sizeof(float), "refit costs");
  st->cost_parts_host.resize(node_count_);
  device_ = std::move(st);
  up_ = {};  // on the device now
  arrivals_ = {};
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
}

bool Bvh8Refit::scan(const std::string& name, const Geometry& geometry) const {
  // Each part checks its share of the vertices and compares its share of
  // the triangles with the lane table's; the first bad vertex is found
  // again after the pass. A float is NaN or infinite when its exponent bits
  // are all ones, which is when adding one to the exponent carries into the
  // sign bit: an OR over those sums, which the compiler vectorises.
  const std::vector<glm::uvec3>& known = device_->triangles;
  const bool compare = known.size() == geometry.triangles.size() && !known.empty();
  const std::size_t values = 3 * geometry.vertices.size(), triangles = compare ? known.size() : 0;
  const float* floats = values ? &geometry.vertices[0].x : nullptr;
  constexpr std::uint32_t kExponent = 0x7f800000u, kExponentOne = 0x00800000u, kSign = 0x80000000u;
  std::atomic<bool> finite{true}, same{compare};
  const unsigned parts = part_count(values + 3 * triangles, 0, kScanPartMin);
  for_each_part(parts, parts, [&](unsigned part, std::size_t, std::size_t) {
    std::uint32_t carries = 0;
    for (std::size_t i = values * part / parts, end = values * (part + 1) / parts; i < end; ++i)
      carries |= (std::bit_cast<std::uint32_t>(floats[i]) & kExponent) + kExponentOne;
    if (carries & kSign) finite.store(false, std::memory_order_relaxed);
    const std::size_t begin = triangles * part / parts, end = triangles * (part + 1) / parts;
    if (end > begin &&
        std::memcmp(known.data() + begin, geometry.triangles.data() + begin, (end - begin) * sizeof(glm::uvec3)))
      same.store(false, std::memory_order_relaxed);
  });
  if (!finite.load())
    for (std::size_t i = 0; i < geometry.vertices.size(); ++i) {
      const glm::vec3& v = geometry.vertices[i];
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
        throw Error(name + " refit of \"" + geometry.source + "\": geometry.vertices[" + std::to_string(i) +
                    "] is not finite");
    }
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
  const bool same = scan(accel.name(), geometry);
  const bool new_triangles = lane_count_ > 0 && !same;
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
      }
      if (!st.counters_clear) {
        cl::Event cleared;
        queue.enqueueFillBuffer(st.counters, cl_uint{0}, 0, node_count_ * sizeof(cl_uint), &last, &cleared);
        last = {cleared};
      }
      const auto block_nodes = static_cast<cl_uint>(block_nodes_.size());
      const auto starts = static_cast<cl_uint>(start_nodes_.size());
      cl_uint a = 0;
      st.bottom_up.setArg(a++, triangle_blocks);
      st.bottom_up.setArg(a++, st.lane_vertices);
      st.bottom_up.setArg(a++, st.vertices);
      st.bottom_up.setArg(a++, nodes);
      st.bottom_up.setArg(a++, st.up);
      st.bottom_up.setArg(a++, st.arrivals);
      st.bottom_up.setArg(a++, st.counters);
      st.bottom_up.setArg(a++, st.block_nodes);
      st.bottom_up.setArg(a++, block_nodes);
      st.bottom_up.setArg(a++, st.start_nodes);
      st.bottom_up.setArg(a++, starts);
      st.bottom_up.setArg(a++, kRefitNodeCost);
      st.bottom_up.setArg(a++, st.cost_parts);
      st.counters_clear = false;  // until the launch is known to have finished
      last = {detail::AccelAccess::launch(accel, st.bottom_up, std::size_t{block_nodes} + starts, last)};
      cl::Event costs_read, root_read;
      queue.enqueueReadBuffer(st.cost_parts, CL_FALSE, 0, node_count_ * sizeof(float), st.cost_parts_host.data(),
                              &last, &costs_read);
      queue.enqueueReadBuffer(nodes, CL_FALSE, 0, sizeof(Bvh8Node), &root, &last, &root_read);
      cl::Event::waitForEvents({costs_read, root_read});
      st.counters_clear = true;
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
