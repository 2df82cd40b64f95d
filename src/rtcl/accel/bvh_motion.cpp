#include "rtcl/accel/bvh_motion.hpp"

#include <algorithm>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <limits>

#include "rtcl/accel/bvh.hpp"
#include "rtcl/accel/bvh_sah.hpp"
#include "rtcl/accel/primitive_blocks.hpp"
#include "rtcl/error.hpp"

namespace rtcl {

namespace {

// Margin covering the float rounding of a linear interpolation between
// keyframes: the kernel computes a + t * (b - a), whose error is a few ulps
// of max(|a|, |b|), once for a vertex and once for an interpolated box
// bound; 8 FLT_EPSILON (16 ulps) of the largest coordinate covers both.
constexpr float kLerpMargin = 8.0f * FLT_EPSILON;

float magnitude(const Aabb& b) {
  glm::vec3 m = glm::max(glm::abs(b.lower), glm::abs(b.upper));
  return std::max({m.x, m.y, m.z});
}

Aabb widened(Aabb b, float m) {
  glm::vec3 margin(kLerpMargin * m);
  b.lower -= margin;
  b.upper += margin;
  return b;
}

// The sphere's box, widened like the static BVH's (centre +- radius rounded
// to float may fall just inside the surface).
Aabb sphere_box(const glm::vec3& c, float r) {
  float m = std::max({std::fabs(c.x), std::fabs(c.y), std::fabs(c.z)}) + r;
  glm::vec3 e(r + 4.0f * FLT_EPSILON * m);
  return {c - e, c + e};
}

Aabb triangle_lane_box(const TriangleBlock& b, int lane) {
  Aabb box;
  for (int v = 0; v < 3; ++v) box.grow(glm::vec3(b.v[v][0][lane], b.v[v][1][lane], b.v[v][2][lane]));
  return box;
}

Aabb sphere_lane_box(const SphereBlock& b, int lane) {
  return sphere_box({b.cx[lane], b.cy[lane], b.cz[lane]}, b.r[lane]);
}

void check_topology(const Geometry& open, const Geometry& close) {
  if (open.vertices.size() != close.vertices.size() || open.triangles != close.triangles ||
      open.spheres.size() != close.spheres.size())
    throw Error("moving geometry " + open.source +
                ": the keyframes at shutter open and close must have the same triangles, vertex and sphere counts");
}

// Both keyframes' boxes of every lane of every node, bottom-up (children
// have larger indices than their parents), widened for interpolation;
// empty lanes hold the finite inverted box [FLT_MAX, -FLT_MAX] so that
// interpolating them stays a miss.
void interpolated_nodes(const Bvh8& bvh, const PrimitiveBlocks& close, std::vector<Bvh8Node>& at_open,
                        std::vector<Bvh8Node>& at_close) {
  at_open = bvh.nodes;
  at_close = bvh.nodes;
  auto node_box = [](const Bvh8Node& n) {
    Aabb box;
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
      if (n.child[lane] == RTCL_CHILD_EMPTY) continue;
      box.grow(Aabb{{n.bounds[0][lane], n.bounds[1][lane], n.bounds[2][lane]},
                    {n.bounds[3][lane], n.bounds[4][lane], n.bounds[5][lane]}});
    }
    return box;
  };
  for (std::size_t i = bvh.nodes.size(); i-- > 0;) {
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) {
      rtcl_i32 child = bvh.nodes[i].child[lane];
      Aabb a, z;
      if (child == RTCL_CHILD_EMPTY) {
        a = z = Aabb{glm::vec3(FLT_MAX), glm::vec3(-FLT_MAX)};
      } else if (child >= 0) {
        a = node_box(at_open[child]);
        z = node_box(at_close[child]);
      } else {
        rtcl_i32 ref = ~child;
        for (int k = 0; k < RTCL_BLOCK_WIDTH; ++k) {
          if (ref & 1) {
            const SphereBlock& sa = bvh.blocks.spheres[ref >> 1];
            if (sa.prim[k] < 0) continue;
            a.grow(sphere_lane_box(sa, k));
            z.grow(sphere_lane_box(close.spheres[ref >> 1], k));
          } else {
            const TriangleBlock& ta = bvh.blocks.triangles[ref >> 1];
            if (ta.prim[k] < 0) continue;
            a.grow(triangle_lane_box(ta, k));
            z.grow(triangle_lane_box(close.triangles[ref >> 1], k));
          }
        }
        float m = std::max(magnitude(a), magnitude(z));
        a = widened(a, m);
        z = widened(z, m);
      }
      for (int axis = 0; axis < 3; ++axis) {
        at_open[i].bounds[axis][lane] = a.lower[axis];
        at_open[i].bounds[3 + axis][lane] = a.upper[axis];
        at_close[i].bounds[axis][lane] = z.lower[axis];
        at_close[i].bounds[3 + axis][lane] = z.upper[axis];
      }
    }
  }
}

}  // namespace

struct MotionBvh::Data {
  Bvh8 bvh;
  PrimitiveBlocks close;                        // bvh.blocks' primitives at shutter close, same lanes
  std::vector<Bvh8Node> nodes_open, nodes_close;  // interpolated bounds only
  std::vector<std::string> defines;
  AccelStats stats;
};

namespace {

std::unique_ptr<MotionBvh::Data> build(const Geometry& open, const Geometry& close, MotionBounds kind) {
  auto start = std::chrono::steady_clock::now();
  check_topology(open, close);
  GeometryReport report = validate(open);
  validate(close);
  auto data = std::make_unique<MotionBvh::Data>();
  std::vector<std::uint32_t> ids = stored_primitives(open);
  auto first_sphere = static_cast<std::size_t>(
      std::partition_point(ids.begin(), ids.end(), [&](std::uint32_t p) { return p < open.triangles.size(); }) -
      ids.begin());
  // Each primitive's swept box: both keyframes' boxes, widened.
  std::vector<Aabb> bounds(ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i) {
    Aabb a, z;
    if (i < first_sphere) {
      a = open.primitive_bounds(ids[i]);
      z = close.primitive_bounds(ids[i]);
    } else {
      const Sphere& sa = open.spheres[ids[i] - open.triangles.size()];
      const Sphere& sz = close.spheres[ids[i] - open.triangles.size()];
      a = sphere_box(sa.center, sa.radius);
      z = sphere_box(sz.center, sz.radius);
    }
    Aabb swept = merge(a, z);
    bounds[i] = widened(swept, magnitude(swept));
  }
  std::span<const Aabb> all_bounds(bounds);
  std::span<const std::uint32_t> all_ids(ids);
  SahConfig sah;
  BuildTree tree = join(build_sah(all_bounds.first(first_sphere), all_ids.first(first_sphere), sah),
                        build_sah(all_bounds.subspan(first_sphere), all_ids.subspan(first_sphere), sah));
  data->bvh = flatten_bvh8(tree, open);
  // The close keyframe in the same blocks and lanes.
  for (const TriangleBlock& b : data->bvh.blocks.triangles) {
    std::vector<std::uint32_t> prims;
    for (int p : b.prim)
      if (p >= 0) prims.push_back(static_cast<std::uint32_t>(p));
    data->close.append(close, prims);
  }
  for (const SphereBlock& b : data->bvh.blocks.spheres) {
    std::vector<std::uint32_t> prims;
    for (int p : b.prim)
      if (p >= 0) prims.push_back(static_cast<std::uint32_t>(p));
    data->close.append(close, prims);
  }
  if (kind == MotionBounds::interpolated) interpolated_nodes(data->bvh, data->close, data->nodes_open, data->nodes_close);
  data->defines = bvh_defines(open, data->bvh);
  if (kind == MotionBounds::interpolated) data->defines.push_back("RTCL_MOTION_LERP_NODES");
  data->stats = bvh_stats(open, report, data->bvh, start);
  data->stats.device_bytes += data->close.bytes();
  if (kind == MotionBounds::interpolated) data->stats.device_bytes += data->bvh.nodes.size() * sizeof(Bvh8Node);
  return data;
}

cl::Buffer upload_nodes(const Device& device, const std::vector<Bvh8Node>& nodes, const char* what) {
  return device.upload(nodes.data(), nodes.size() * sizeof(Bvh8Node), what);
}

}  // namespace

MotionBvh::MotionBvh(const Device& device, const Geometry& open, const Geometry& close, MotionBounds bounds,
                     const AccelConfig& config)
    : MotionBvh(device, build(open, close, bounds), bounds, config) {}

MotionBvh::MotionBvh(const Device& device, std::unique_ptr<Data> d, MotionBounds bounds, const AccelConfig& config)
    : Accel(device, "bvh-motion", TraceKernels{"accel/bvh_motion.cl", 1, 1, false}, std::nullopt, d->defines, d->stats, config),
      bounds_(bounds) {
  const bool lerp = bounds == MotionBounds::interpolated;
  nodes_ = upload_nodes(device, lerp ? d->nodes_open : d->bvh.nodes, "motion BVH nodes");
  nodes_close_ = lerp ? upload_nodes(device, d->nodes_close, "motion BVH nodes at close") : nodes_;
  DevicePrimitives open = upload(device, d->bvh.blocks), close = upload(device, d->close);
  tri_open_ = open.triangles;
  tri_close_ = close.triangles;
  sph_open_ = open.spheres;
  sph_close_ = close.spheres;
}

void MotionBvh::set_call_args(cl::Kernel& kernel) const {
  if (!times_) throw Error(name() + " trace: the rays need times (MotionBvh::trace with RayTimes)");
  kernel.setArg(3, times_->buffer);
  kernel.setArg(4, static_cast<cl_uint>(times_->stride));
  kernel.setArg(5, static_cast<cl_uint>(times_->offset));
}

void MotionBvh::set_structure_args(cl::Kernel& kernel, cl_uint first) const {
  cl_uint a = first + 3;  // after the call arguments
  kernel.setArg(a++, nodes_);
  if (bounds_ == MotionBounds::interpolated) kernel.setArg(a++, nodes_close_);
  kernel.setArg(a++, tri_open_);
  kernel.setArg(a++, tri_close_);
  kernel.setArg(a++, sph_open_);
  kernel.setArg(a++, sph_close_);
}

cl::Event MotionBvh::trace(Query query, const cl::Buffer& rays, const RayTimes& times, const cl::Buffer& hits,
                           std::size_t ray_count, const std::vector<cl::Event>& wait, Coherence coherence) const {
  std::size_t need = ray_count == 0 ? 0 : (std::size_t(ray_count) - 1) * times.stride + times.offset + 1;
  std::size_t have = with_cl_errors([&] { return times.buffer.getInfo<CL_MEM_SIZE>(); }) / sizeof(float);
  if (have < need)
    throw Error(name() + " trace: the time buffer holds " + std::to_string(have) + " floats, " + std::to_string(need) +
                " needed for " + std::to_string(ray_count) + " rays");
  times_ = &times;
  struct Reset {
    const RayTimes*& t;
    ~Reset() { t = nullptr; }
  } reset{times_};
  return Accel::trace(query, rays, hits, ray_count, wait, coherence);
}

const char* motion_bounds_name(MotionBounds bounds) {
  return bounds == MotionBounds::swept ? "swept" : "interpolated";
}

}  // namespace rtcl
