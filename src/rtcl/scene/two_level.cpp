#include "rtcl/scene/two_level.hpp"

#include <algorithm>
#include <bit>
#include <cfloat>
#include <cmath>
#include <sstream>

#include "rtcl/accel/accel_state.hpp"
#include "rtcl/accel/bvh_sah.hpp"
#include "rtcl/error.hpp"
#include "rtcl/parallel.hpp"
#include "rtcl/scene/motion.hpp"

namespace rtcl {

namespace {

std::string number(double x) {
  std::ostringstream out;
  out << x;
  return out.str();
}

// Largest magnitude of the box's coordinates.
double magnitude(const Aabb& b) {
  glm::dvec3 m = glm::max(glm::abs(glm::dvec3(b.lower)), glm::abs(glm::dvec3(b.upper)));
  return std::max({m.x, m.y, m.z});
}

// Grows [lower, upper] by the boxes of `roots` under the transform x ->
// A x + T (float, m row-major): per output axis i, T_i plus for each j the
// lesser (greater) of A_ij lower_j and A_ij upper_j, the bound of the
// box's eight corners (Arvo 1990, "Transforming axis-aligned bounding
// boxes"). Each bound is pushed out by 2^-20 (16 float ulps) of the sum of
// its four terms' magnitudes, more than the rounding of the products, of
// the sum (together at most about 4 ulps of that sum; Higham 2002,
// "Accuracy and stability of numerical algorithms", 4.2) and of the
// margin's subtraction: the float box contains the exact image. The
// eight lanes are the root's children (padded with copies of the first);
// the loops over them vectorise.
void grow_transformed(const RootBoxes& roots, const Transform& m, glm::vec3& lower, glm::vec3& upper) {
  for (int i = 0; i < 3; ++i) {
    float lo[RTCL_BLOCK_WIDTH], hi[RTCL_BLOCK_WIDTH];
    const float t = m.m[i][3];
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
      float l = t, h = t, size = std::abs(t);
      for (int j = 0; j < 3; ++j) {
        const float p = m.m[i][j] * roots.lower[j][lane], q = m.m[i][j] * roots.upper[j][lane];
        l += std::min(p, q);
        h += std::max(p, q);
        size += std::max(std::abs(p), std::abs(q));
      }
      const float margin = size * 0x1p-20f;
      lo[lane] = l - margin;
      hi[lane] = h + margin;
    }
    // reduced in locals: through the references, each step waited for the
    // store of the one before (twice the whole function's time)
    float low = lower[i], high = upper[i];
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
      low = std::min(low, lo[lane]);
      high = std::max(high, hi[lane]);
    }
    lower[i] = low;
    upper[i] = high;
  }
}

// Records of an instance: `record` always, `motion` for a moving one.
InstanceRecord instance_record(const PlacedInstance& p, std::uint32_t motion_index) {
  InstanceRecord r{};
  r.bottom = p.bottom;
  r.user_id = p.user_id;
  if (p.at_close) {
    r.flags = RTCL_INSTANCE_MOVING;
    r.motion = motion_index;
    return r;
  }
  const glm::dmat3 inverse = glm::inverse(linear_part(p.transform));
  bool identity = true;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) {
      // glm is column-major: inverse[col][row] is row `row`, column `col`.
      r.to_object[3 * row + col] = static_cast<float>(inverse[col][row]);
      identity = identity && p.transform.m[row][col] == (row == col ? 1.0f : 0.0f);
    }
  for (int row = 0; row < 3; ++row) r.translation[row] = p.transform.m[row][3];
  if (identity) {
    r.flags = RTCL_INSTANCE_LINEAR_IDENTITY;
    for (int k = 0; k < 9; ++k) r.to_object[k] = k % 4 == 0 ? 1.0f : 0.0f;
    // the world ray is the object ray: one flag test in the kernel
    if (r.translation[0] == 0.0f && r.translation[1] == 0.0f && r.translation[2] == 0.0f)
      r.flags |= RTCL_INSTANCE_IDENTITY;
  }
  return r;
}

InstanceMotion motion_record(const PlacedInstance& p) {
  InstanceMotion m{};
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 4; ++col) {
      m.open[4 * row + col] = p.transform.m[row][col];
      m.close[4 * row + col] = p.at_close->m[row][col];
    }
  return m;
}

// A node whose eight slots are empty.
Bvh8Node empty_node() {
  Bvh8Node n;
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
    for (int axis = 0; axis < 3; ++axis) {
      n.bounds[axis][lane] = INFINITY;
      n.bounds[3 + axis][lane] = -INFINITY;
    }
    n.child[lane] = RTCL_CHILD_EMPTY;
  }
  return n;
}

// The 8-wide top level collapsed from the binary SAH tree (leaves of up to
// eight instances). A wide node's lanes are items: an instance, or a
// binary node (inner, or a leaf of several instances) that becomes a wide
// node of its own below. A node starts as its binary node opened and
// greedily opens the item of largest area that still fits: an inner node
// into its two children, a leaf into its instances. Fixed-size arrays
// alone: a commit of 100k instances forms some 20k nodes.
struct TopCollapse {
  const BuildTree& tree;
  std::span<const Aabb> boxes;  // the instances' world boxes
  TopLevel& out;

  struct Item {
    std::uint32_t index;  // instance, or binary node
    bool instance;
  };

  Item item_of(std::uint32_t binary) const {
    const BuildNode& n = tree.nodes[binary];
    return n.is_leaf() && n.count == 1 ? Item{tree.prims[n.first], true} : Item{binary, false};
  }

  // Forms the wide node `index` from binary node `binary`; `stack` is the
  // entries its ancestors leave on the traversal stack.
  void form(std::uint32_t binary, std::size_t index, std::uint32_t stack) {
    Item items[RTCL_BLOCK_WIDTH];
    std::uint32_t count = 1;
    items[0] = {binary, false};
    const auto open = [&](std::uint32_t k) {
      const BuildNode& n = tree.nodes[items[k].index];
      if (n.is_leaf()) {
        items[k] = {tree.prims[n.first], true};
        for (std::uint32_t p = 1; p < n.count; ++p) items[count++] = {tree.prims[n.first + p], true};
      } else {
        items[count++] = item_of(n.child[1]);
        items[k] = item_of(n.child[0]);
      }
    };
    for (int best = 0; best >= 0;) {
      open(static_cast<std::uint32_t>(best));
      best = -1;
      float best_area = -1.0f;
      for (std::uint32_t k = 0; k < count; ++k) {
        if (items[k].instance) continue;
        const BuildNode& n = tree.nodes[items[k].index];
        const std::uint32_t grows = n.is_leaf() ? n.count - 1 : 1;
        if (count + grows <= RTCL_BLOCK_WIDTH && n.bounds.area() > best_area) {
          best = static_cast<int>(k);
          best_area = n.bounds.area();
        }
      }
    }
    out.stack_size = std::max(out.stack_size, stack + count);
    const std::size_t first_below = out.nodes.size();
    std::uint32_t below[RTCL_BLOCK_WIDTH];
    std::uint32_t below_count = 0;
    Bvh8Node& node = out.nodes[index];
    for (std::uint32_t lane = 0; lane < count; ++lane) {
      const Item& item = items[lane];
      const Aabb& box = item.instance ? boxes[item.index] : tree.nodes[item.index].bounds;
      for (int axis = 0; axis < 3; ++axis) {
        node.bounds[axis][lane] = box.lower[axis];
        node.bounds[3 + axis][lane] = box.upper[axis];
      }
      if (item.instance) {
        node.child[lane] = ~static_cast<rtcl_i32>(item.index);
      } else {
        node.child[lane] = static_cast<rtcl_i32>(first_below + below_count);
        below[below_count++] = item.index;
      }
    }
    out.nodes.resize(first_below + below_count, empty_node());
    for (std::uint32_t b = 0; b < below_count; ++b) form(below[b], first_below + b, stack + count - 1);
  }
};


// Instances per host thread in the pass over them and in the top level's
// build (parallel.hpp). A commit's pooled threads have usually slept (after
// the set_transform calls), and waking one took 0.1-0.3 ms here; 4096
// instances are about 0.4 ms of one thread's work: a commit of 10k
// instances took 2.7-3.5 ms on two threads against 4.2-4.8 ms on one
// (docs/benchmarks.md, "Instances"); two threads from 8192 instances.
constexpr std::size_t kInstancesPerPart = 4096;

// The top level's RTCL_TOP_STACK_SIZE: a power of two, at least 64, so
// that commits of a changing top level reuse one compiled program.
std::uint32_t top_kernel_stack_size(std::uint32_t stack_size) {
  return std::max<std::uint32_t>(64, std::bit_ceil(stack_size));
}

}  // namespace

glm::dmat3 linear_part(const Transform& t) {
  glm::dmat3 a;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) a[col][row] = t.m[row][col];
  return a;
}

glm::dvec3 translation_part(const Transform& t) { return {t.m[0][3], t.m[1][3], t.m[2][3]}; }

std::string transform_problem(const Transform& transform) {
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 4; ++col)
      if (!std::isfinite(transform.m[row][col]))
        return "transform element [" + std::to_string(row) + "][" + std::to_string(col) + "] is " +
               number(transform.m[row][col]) + " (must be finite)";
  const glm::dmat3 a = linear_part(transform);
  double rows = 1.0;
  for (int row = 0; row < 3; ++row) rows *= glm::length(glm::dvec3(a[0][row], a[1][row], a[2][row]));
  const double det = glm::determinant(a);
  if (!(rows > 0.0) || !(std::abs(det) > std::ldexp(rows, -20)))
    return "transform is singular: its 3x3 part has determinant " + number(det) +
           " (it must not flatten the mesh onto a plane, a line or a point)";
  const glm::dmat3 inverse = glm::inverse(a);
  for (int col = 0; col < 3; ++col)
    for (int row = 0; row < 3; ++row)
      if (!std::isfinite(static_cast<float>(inverse[col][row])))
        return "transform's inverse is not finite in float (a scale too small for float)";
  return "";
}

std::string motion_problem(const Transform& open, const Transform& close) {
  if (std::string problem = transform_problem(open); !problem.empty()) return "at shutter open, " + problem;
  if (std::string problem = transform_problem(close); !problem.empty()) return "at shutter close, " + problem;
  if (!blend_keeps_determinant_sign(linear_part(open), linear_part(close), 0.0, 1.0))
    return "the blend of its two transforms is singular at some time in [0, 1] (the mesh would collapse onto a "
           "plane; a rotation of 180 degrees or more cannot be blended)";
  return "";
}

RootBoxes root_boxes_of(const MeshBuild& mesh) {
  RootBoxes r;
  const std::size_t count = mesh.root_boxes.size();
  for (std::size_t lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
    // a mesh without boxes places the point at its origin
    const Aabb box = count == 0 ? Aabb{glm::vec3(0.0f), glm::vec3(0.0f)} : mesh.root_boxes[lane < count ? lane : 0];
    for (int axis = 0; axis < 3; ++axis) {
      r.lower[axis][lane] = box.lower[axis];
      r.upper[axis][lane] = box.upper[axis];
    }
  }
  return r;
}

Aabb instance_world_box(const RootBoxes& roots, const Transform& transform, const std::optional<Transform>& at_close) {
  Aabb box;  // empty
  grow_transformed(roots, transform, box.lower, box.upper);
  if (at_close) grow_transformed(roots, *at_close, box.lower, box.upper);
  const auto widen = static_cast<float>(kInstanceBoxWiden * magnitude(box));
  box.lower -= glm::vec3(widen);
  box.upper += glm::vec3(widen);
  return box;
}

TopLevel build_top_level(std::span<const Aabb> world_boxes) {
  TopLevel top;
  build_top_level(world_boxes, top);
  return top;
}

void build_top_level(std::span<const Aabb> world_boxes, TopLevel& top) {
  top.nodes.clear();
  top.nodes.push_back(empty_node());
  top.stack_size = 1;
  if (world_boxes.empty()) return;
  std::vector<std::uint32_t> ids(world_boxes.size());
  for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = static_cast<std::uint32_t>(i);
  // Leaves of up to eight instances, each opened into the lanes of one
  // wide node (TopCollapse).
  SahConfig sah;
  sah.thread_count = part_count(world_boxes.size(), 0, kInstancesPerPart);
  BuildTree tree = build_sah(world_boxes, ids, sah);
  top.stack_size = 0;
  TopCollapse{tree, world_boxes, top}.form(0, 0, 0);
  if (top.stack_size > kBvhMaxStackSize)
    throw Error("Scene::commit: the top level needs a traversal stack of " + std::to_string(top.stack_size) +
                " entries, more than " + std::to_string(kBvhMaxStackSize));
}

DeviceBottoms upload_bottoms(const Device& device, std::span<const std::shared_ptr<const MeshBuild>> meshes) {
  std::vector<BottomLevel> levels;
  std::size_t nodes = 0, triangles = 0, spheres = 0;
  DeviceBottoms out;
  for (const auto& mesh : meshes) {
    const Bvh8& bvh = mesh->built.bvh;
    levels.push_back({static_cast<rtcl_u32>(nodes), static_cast<rtcl_u32>(triangles),
                      static_cast<rtcl_u32>(spheres), 0});
    nodes += bvh.nodes.size();
    triangles += bvh.blocks.triangles.size();
    spheres += bvh.blocks.spheres.size();
    out.stack_size = std::max(out.stack_size, bvh.stack_size);
    out.spheres_present = out.spheres_present || !bvh.blocks.spheres.empty();
  }
  if (nodes > 0x7fffffffu || triangles > 0x3fffffffu || spheres > 0x3fffffffu)
    throw Error("Scene::commit: the meshes' bottom levels hold more nodes or blocks than 32-bit offsets reach");
  // One placeholder record where a kind is absent: kernel arguments never change.
  std::vector<Bvh8Node> all_nodes;
  all_nodes.reserve(std::max<std::size_t>(nodes, 1));
  std::vector<TriangleBlock> all_triangles;
  all_triangles.reserve(std::max<std::size_t>(triangles, 1));
  std::vector<SphereBlock> all_spheres;
  all_spheres.reserve(std::max<std::size_t>(spheres, 1));
  for (const auto& mesh : meshes) {
    const Bvh8& bvh = mesh->built.bvh;
    all_nodes.insert(all_nodes.end(), bvh.nodes.begin(), bvh.nodes.end());
    all_triangles.insert(all_triangles.end(), bvh.blocks.triangles.begin(), bvh.blocks.triangles.end());
    all_spheres.insert(all_spheres.end(), bvh.blocks.spheres.begin(), bvh.blocks.spheres.end());
  }
  if (all_nodes.empty()) all_nodes.push_back(empty_node());
  if (all_triangles.empty()) all_triangles.push_back(empty_triangle_block());
  if (all_spheres.empty()) all_spheres.push_back(empty_sphere_block());
  if (levels.empty()) levels.push_back({});
  out.bytes = levels.size() * sizeof(BottomLevel) + all_nodes.size() * sizeof(Bvh8Node) +
              all_triangles.size() * sizeof(TriangleBlock) + all_spheres.size() * sizeof(SphereBlock);
  out.levels = device.upload(levels.data(), levels.size() * sizeof(BottomLevel), "the scene's bottom levels' offsets");
  out.nodes = device.upload(all_nodes.data(), all_nodes.size() * sizeof(Bvh8Node), "the scene's bottom levels' nodes");
  out.triangles = device.upload(all_triangles.data(), all_triangles.size() * sizeof(TriangleBlock),
                                "the scene's bottom levels' triangle blocks");
  out.spheres = device.upload(all_spheres.data(), all_spheres.size() * sizeof(SphereBlock),
                              "the scene's bottom levels' sphere blocks");
  return out;
}

TwoLevel::TwoLevel(const Device& device, Precision precision, std::shared_ptr<const DeviceBottoms> bottoms,
                   std::span<const std::shared_ptr<const MeshBuild>> meshes, std::span<const PlacedInstance> instances,
                   const TwoLevel* previous)
    : device_(device), bottoms_(std::move(bottoms)) {
  scratch_ = previous ? previous->scratch_ : std::make_shared<TopScratch>();
  TopScratch& scratch = *scratch_;
  // Moving instance i's motion record is the number of moving ones before it.
  std::vector<std::uint32_t>& motion_index = scratch.motion_index;
  motion_index.resize(instances.size());
  std::uint32_t moving = 0;
  for (std::size_t i = 0; i < instances.size(); ++i) {
    motion_index[i] = moving;
    moving += instances[i].at_close ? 1 : 0;
  }
  std::vector<RootBoxes> roots;
  for (const auto& mesh : meshes) roots.push_back(root_boxes_of(*mesh));
  std::vector<Aabb>& boxes = scratch.boxes;
  std::vector<InstanceRecord>& records = scratch.records;
  std::vector<InstanceMotion>& motions = scratch.motions;
  boxes.resize(instances.size());
  records.resize(instances.size());
  motions.resize(moving);
  for_each_part(instances.size(), part_count(instances.size(), 0, kInstancesPerPart),
                [&](unsigned, std::size_t begin, std::size_t end) {
                  for (std::size_t i = begin; i < end; ++i) {
                    const PlacedInstance& p = instances[i];
                    boxes[i] = instance_world_box(roots[p.bottom], p.transform, p.at_close);
                    records[i] = instance_record(p, motion_index[i]);
                    if (p.at_close) motions[motion_index[i]] = motion_record(p);
                  }
                });
  moving_ = moving > 0;
  TopLevel& top = scratch.top;
  build_top_level(boxes, top);
  if (records.empty()) records.push_back({});
  if (motions.empty()) motions.push_back({});
  bytes_ = top.nodes.size() * sizeof(Bvh8Node) + records.size() * sizeof(InstanceRecord) +
           motions.size() * sizeof(InstanceMotion);
  top_ = device.upload(top.nodes.data(), top.nodes.size() * sizeof(Bvh8Node), "scene top-level nodes");
  instances_ = device.upload(records.data(), records.size() * sizeof(InstanceRecord), "scene instances");
  if (!moving_ && previous && !previous->moving_)  // both the one-record placeholder, never written
    motions_ = previous->motions_;
  else
    motions_ = device.upload(motions.data(), motions.size() * sizeof(InstanceMotion), "scene instance motions");
  if (previous) {  // read only (times) and never written (ids): shared
    no_times_ = previous->no_times_;
    no_ids_ = previous->no_ids_;
  } else {
    const float zero = 0.0f;
    no_times_ = device.upload(&zero, sizeof(float), "scene ray times placeholder");
    no_ids_ = device.allocate(sizeof(cl_uint), "scene instance ids placeholder");
  }
  require_precision(device.info(), precision);
  defines_ = {"RTCL_STACK_SIZE=" + std::to_string(bvh_kernel_stack_size(bottoms_->stack_size)),
              "RTCL_TOP_STACK_SIZE=" + std::to_string(top_kernel_stack_size(top.stack_size))};
  if (bottoms_->spheres_present) defines_.push_back("RTCL_HAS_SPHERES");
  if (moving_) defines_.push_back("RTCL_INSTANCES_MOVING");
  if (instances.size() == 1) defines_.push_back("RTCL_TOP_ONE_INSTANCE");
  for (std::string& option : precision_build_options(precision)) defines_.push_back(std::move(option));
  if (previous && previous->defines_ == defines_) {
    std::lock_guard lock(previous->mutex_);
    for (int q = 0; q < 2; ++q) programs_[q] = previous->programs_[q];
  }
  std::lock_guard lock(mutex_);
  if (!programs_[0])  // a program that fails to build fails the commit
    programs_[0] = device_.program("accel/instances.cl", with_query(defines_, Query::closest));
}

std::vector<std::string> TwoLevel::with_query(std::vector<std::string> defines, Query query) {
  defines.push_back(query == Query::closest ? "RTCL_QUERY_CLOSEST" : "RTCL_QUERY_ANY");
  return defines;
}

cl::Kernel& TwoLevel::kernel(Query query) const {
  const int q = query == Query::closest ? 0 : 1;
  std::optional<cl::Kernel>& slot = kernels_[q];
  if (slot) return *slot;
  if (!programs_[q]) programs_[q] = device_.program("accel/instances.cl", with_query(defines_, query));
  const cl::Program& program = *programs_[q];
  with_cl_errors([&] {
    cl::Kernel k(program, query == Query::closest ? "trace_closest_instances" : "trace_any_instances");
    cl_uint a = 8;  // after rays, hits, ray_count, instance_ids, write_ids, times, time_stride, time_offset
    k.setArg(a++, top_);
    k.setArg(a++, instances_);
    k.setArg(a++, motions_);
    k.setArg(a++, bottoms_->levels);
    k.setArg(a++, bottoms_->nodes);
    k.setArg(a++, bottoms_->triangles);
    k.setArg(a++, bottoms_->spheres);
    slot = std::move(k);
  });
  return *slot;
}

cl::Event TwoLevel::trace(Query query, const cl::Buffer& rays, const cl::Buffer& hits, std::size_t ray_count,
                          const cl::Buffer* instance_ids, const cl::Buffer* times, std::uint32_t time_stride,
                          std::uint32_t time_offset, const std::vector<cl::Event>& wait) const {
  std::lock_guard lock(mutex_);
  return with_cl_errors([&] {
    cl::Kernel& k = kernel(query);
    k.setArg(0, rays);
    k.setArg(1, hits);
    k.setArg(2, static_cast<cl_uint>(ray_count));
    k.setArg(3, instance_ids ? *instance_ids : no_ids_);
    k.setArg(4, static_cast<cl_uint>(instance_ids ? 1 : 0));
    k.setArg(5, times ? *times : no_times_);
    k.setArg(6, static_cast<cl_uint>(times ? time_stride : 0));
    k.setArg(7, static_cast<cl_uint>(times ? time_offset : 0));
    return detail::launch_items(device_, k, ray_count, wait);
  });
}

}  // namespace rtcl
