#include "bench/support/embree_baseline.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>

#include "rtcl/error.hpp"

namespace rtcl::bench {

namespace {

// Bytes Embree holds right now, from its memory monitor (allocations are
// reported positive, frees negative).
std::atomic<long long> embree_live_bytes{0};

bool monitor_memory(void*, ssize_t bytes, bool) {
  embree_live_bytes += bytes;
  return true;
}

// One Embree device per process; its TBB arena gets the first caller's
// thread count. $RTCL_EMBREE_CONFIG, where set, is appended to the device's
// configuration (Embree's rtcNewDevice syntax; e.g. verbose=3 prints the
// statistics of every BVH it builds).
RTCDevice embree_device(unsigned threads) {
  static RTCDevice device = [threads] {
    std::string config = "threads=" + std::to_string(std::max(threads, 1u));
    if (const char* extra = std::getenv("RTCL_EMBREE_CONFIG"); extra && *extra) config += std::string(",") + extra;
    RTCDevice d = rtcNewDevice(config.c_str());
    if (!d) throw Error("Embree: rtcNewDevice(\"" + config + "\") failed (error " +
                        std::to_string(rtcGetDeviceError(nullptr)) + ")");
    rtcSetDeviceMemoryMonitorFunction(d, monitor_memory, nullptr);
    return d;
  }();
  return device;
}

void check_embree(RTCDevice device, const char* what) {
  RTCError error = rtcGetDeviceError(device);
  if (error != RTC_ERROR_NONE) throw Error(std::string("Embree: ") + what + " failed (RTCError " + std::to_string(error) + ")");
}

constexpr std::size_t block_rays = 1024;  // rays a thread takes from the shared counter at once (a multiple of 8)

RTCRay to_embree(const Ray& r) {
  RTCRay ray;
  ray.org_x = r.ox, ray.org_y = r.oy, ray.org_z = r.oz;
  ray.dir_x = r.dx, ray.dir_y = r.dy, ray.dir_z = r.dz;
  ray.tnear = r.tmin;
  ray.tfar = r.tmax;
  ray.time = 0.0f;
  ray.mask = ~0u;
  ray.id = 0;
  ray.flags = 0;
  return ray;
}

// Answers the prepared records [begin, end) in place.
void closest(RTCScene scene, RTCRayHit* records, std::size_t begin, std::size_t end) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  for (std::size_t i = begin; i < end; ++i) rtcIntersect1(scene, &context, &records[i]);
}

void occluded(RTCScene scene, RTCRayHit* records, std::size_t begin, std::size_t end) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  for (std::size_t i = begin; i < end; ++i) rtcOccluded1(scene, &context, &records[i].ray);
}

// Packets [begin / 8, end / 8) answered in place; the last packet's lanes
// past the ray count are invalid (`valid` 0).
// Embree reads packets and their valid masks with 32-byte aligned loads.
struct alignas(32) ValidMask {
  int lane[8];
};
struct PacketRecords {
  std::vector<RTCRayHit8> packets;  // RTCRayHit8 is declared 32-byte aligned
  std::vector<ValidMask> valid;
};

void closest8(RTCScene scene, PacketRecords& records, std::size_t begin, std::size_t end) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  for (std::size_t p = begin / 8; p < (end + 7) / 8; ++p)
    rtcIntersect8(records.valid[p].lane, scene, &context, &records.packets[p]);
}

void occluded8(RTCScene scene, PacketRecords& records, std::size_t begin, std::size_t end) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  for (std::size_t p = begin / 8; p < (end + 7) / 8; ++p)
    rtcOccluded8(records.valid[p].lane, scene, &context, &records.packets[p].ray);
}

}  // namespace

const char* embree_api_name(EmbreeApi api, Query query) {
  if (api == EmbreeApi::packet8) return query == Query::closest ? "rtcIntersect8" : "rtcOccluded8";
  return query == Query::closest ? "rtcIntersect1" : "rtcOccluded1";
}

// Embree reads vertices with 16-byte loads: the vertex array carries one
// float of padding after the last vertex. Spheres are Embree's sphere
// points, (x, y, z, radius) per sphere.
struct EmbreeScene::Buffers {
  std::vector<float> vertices;
  std::vector<std::uint32_t> indices;
  std::vector<float> spheres;
};

namespace {
// Geometry ids in Embree's scene (rtcAttachGeometryByID).
constexpr unsigned triangles_geometry_id = 0;
constexpr unsigned spheres_geometry_id = 1;

// Embree's closest hit as rtcl reports it: primitive ids count the
// triangles first, then the spheres, and a sphere's u = v = 0
// (docs/file-formats.md).
Hit embree_hit(float t, float u, float v, unsigned geom_id, unsigned prim_id, std::size_t triangle_count) {
  if (geom_id != spheres_geometry_id) return Hit{t, u, v, static_cast<rtcl_i32>(prim_id)};
  return Hit{t, 0.0f, 0.0f, static_cast<rtcl_i32>(triangle_count + prim_id)};
}
}  // namespace

EmbreeScene::EmbreeScene(const Geometry& geometry, EmbreeQuality quality, unsigned threads, bool robust)
    : buffers_(new Buffers) {
  try {
    build(geometry, quality, threads, robust);
  } catch (...) {
    release();
    throw;
  }
}

void EmbreeScene::build(const Geometry& geometry, EmbreeQuality quality, unsigned threads, bool robust) {
  RTCDevice device = embree_device(threads);
  buffers_->vertices.reserve(3 * geometry.vertices.size() + 1);
  for (const glm::vec3& v : geometry.vertices) buffers_->vertices.insert(buffers_->vertices.end(), {v.x, v.y, v.z});
  buffers_->vertices.push_back(0.0f);
  buffers_->indices.reserve(3 * geometry.triangles.size());
  for (const glm::uvec3& t : geometry.triangles) buffers_->indices.insert(buffers_->indices.end(), {t.x, t.y, t.z});
  buffers_->spheres.reserve(4 * geometry.spheres.size());
  for (const Sphere& sp : geometry.spheres)
    buffers_->spheres.insert(buffers_->spheres.end(), {sp.center.x, sp.center.y, sp.center.z, sp.radius});
  if (!geometry.spheres.empty() && !rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_POINT_GEOMETRY_SUPPORTED))
    throw Error("Embree: this Embree was built without point geometry, so it cannot trace the spheres of " +
                geometry.source);

  long long bytes_before = embree_live_bytes.load();
  auto start = std::chrono::steady_clock::now();
  RTCScene scene = rtcNewScene(device);
  check_embree(device, "rtcNewScene");
  scene_ = scene;
  rtcSetSceneFlags(scene, robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
  rtcSetSceneBuildQuality(scene, quality == EmbreeQuality::high ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM);
  if (!geometry.triangles.empty()) {
    RTCGeometry mesh = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(mesh, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, buffers_->vertices.data(), 0,
                               3 * sizeof(float), geometry.vertices.size());
    rtcSetSharedGeometryBuffer(mesh, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, buffers_->indices.data(), 0,
                               3 * sizeof(std::uint32_t), geometry.triangles.size());
    if (quality == EmbreeQuality::high) rtcSetGeometryBuildQuality(mesh, RTC_BUILD_QUALITY_HIGH);
    rtcCommitGeometry(mesh);
    rtcAttachGeometryByID(scene, mesh, triangles_geometry_id);
    rtcReleaseGeometry(mesh);
  }
  if (!geometry.spheres.empty()) {
    RTCGeometry points = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    rtcSetSharedGeometryBuffer(points, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, buffers_->spheres.data(), 0,
                               4 * sizeof(float), geometry.spheres.size());
    if (quality == EmbreeQuality::high) rtcSetGeometryBuildQuality(points, RTC_BUILD_QUALITY_HIGH);
    rtcCommitGeometry(points);
    rtcAttachGeometryByID(scene, points, spheres_geometry_id);
    rtcReleaseGeometry(points);
  }
  rtcCommitScene(scene);
  auto stop = std::chrono::steady_clock::now();
  check_embree(device, "building the scene");
  build_ms_ = std::chrono::duration<double, std::milli>(stop - start).count();
  bytes_ = static_cast<std::size_t>(std::max(0LL, embree_live_bytes.load() - bytes_before));
}

EmbreeScene::~EmbreeScene() { release(); }

void EmbreeScene::release() {
  if (scene_) rtcReleaseScene(static_cast<RTCScene>(scene_));
  scene_ = nullptr;
  delete buffers_;
  buffers_ = nullptr;
}

struct EmbreeScene::Prepared {
  Query query = Query::closest;
  EmbreeApi api = EmbreeApi::single;
  std::size_t count = 0;
  std::vector<RTCRayHit> records;  // single
  PacketRecords packets;           // packet8
};

void EmbreeScene::prepare(Query query, const Ray* rays, std::size_t count, EmbreeApi api) const {
  if (!prepared_) prepared_ = std::make_shared<Prepared>();
  prepared_->query = query;
  prepared_->api = api;
  prepared_->count = count;
  if (api == EmbreeApi::single) {
    prepared_->records.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
      RTCRayHit& rh = prepared_->records[i];
      rh.ray = to_embree(rays[i]);
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    }
    return;
  }
  PacketRecords& p = prepared_->packets;
  p.packets.resize((count + 7) / 8);
  p.valid.assign(p.packets.size(), {});
  for (std::size_t i = 0; i < 8 * p.packets.size(); ++i) {
    RTCRayHit8& rh = p.packets[i / 8];
    const std::size_t l = i % 8;
    const Ray r = i < count ? rays[i] : Ray{0, 0, 0, 0, 0, 1, 0, 0};
    p.valid[i / 8].lane[l] = i < count ? -1 : 0;
    rh.ray.org_x[l] = r.ox, rh.ray.org_y[l] = r.oy, rh.ray.org_z[l] = r.oz;
    rh.ray.dir_x[l] = r.dx, rh.ray.dir_y[l] = r.dy, rh.ray.dir_z[l] = r.dz;
    rh.ray.tnear[l] = r.tmin;
    rh.ray.tfar[l] = r.tmax;
    rh.ray.time[l] = 0.0f;
    rh.ray.mask[l] = ~0u;
    rh.ray.id[l] = 0;
    rh.ray.flags[l] = 0;
    rh.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
  }
}

void EmbreeScene::trace_prepared(unsigned threads) const {
  RTCScene scene = static_cast<RTCScene>(scene_);
  Prepared& prepared = *prepared_;
  const std::size_t count = prepared.count;
  auto range = [&](std::size_t begin, std::size_t end) {
    if (prepared.api == EmbreeApi::packet8)
      (prepared.query == Query::closest ? closest8 : occluded8)(scene, prepared.packets, begin, end);
    else
      (prepared.query == Query::closest ? closest : occluded)(scene, prepared.records.data(), begin, end);
  };
  std::atomic<std::size_t> next{0};
  auto work = [&] {
    for (;;) {
      std::size_t begin = next.fetch_add(block_rays);
      if (begin >= count) return;
      range(begin, std::min(count, begin + block_rays));
    }
  };
  std::vector<std::thread> helpers;
  for (unsigned t = 1; t < std::max(threads, 1u); ++t) helpers.emplace_back(work);
  work();
  for (auto& h : helpers) h.join();
}

void EmbreeScene::answers(Hit* hits) const {
  const float inf = std::numeric_limits<float>::infinity();
  const std::size_t triangle_count = buffers_->indices.size() / 3;
  const Prepared& prepared = *prepared_;
  if (prepared.api == EmbreeApi::packet8) {
    for (std::size_t i = 0; i < prepared.count; ++i) {
      const RTCRayHit8& rh = prepared.packets.packets[i / 8];
      const std::size_t l = i % 8;
      if (prepared.query == Query::any)  // rtcOccluded8 sets tfar = -inf where the ray is blocked
        hits[i] = rh.ray.tfar[l] == -inf ? Hit{rh.ray.tnear[l], 0.0f, 0.0f, 0} : Hit{inf, 0.0f, 0.0f, -1};
      else if (rh.hit.geomID[l] == RTC_INVALID_GEOMETRY_ID)
        hits[i] = Hit{inf, 0.0f, 0.0f, -1};
      else
        hits[i] = embree_hit(rh.ray.tfar[l], rh.hit.u[l], rh.hit.v[l], rh.hit.geomID[l], rh.hit.primID[l],
                             triangle_count);
    }
    return;
  }
  const std::vector<RTCRayHit>& records = prepared.records;
  for (std::size_t i = 0; i < records.size(); ++i) {
    const RTCRayHit& rh = records[i];
    if (prepared.query == Query::any)  // rtcOccluded1 sets tfar = -inf when the ray is blocked
      hits[i] = rh.ray.tfar == -inf ? Hit{rh.ray.tnear, 0.0f, 0.0f, 0} : Hit{inf, 0.0f, 0.0f, -1};
    else if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
      hits[i] = Hit{inf, 0.0f, 0.0f, -1};
    else
      hits[i] = embree_hit(rh.ray.tfar, rh.hit.u, rh.hit.v, rh.hit.geomID, rh.hit.primID, triangle_count);
  }
}

void EmbreeScene::trace(Query query, const Ray* rays, Hit* hits, std::size_t count, unsigned threads,
                        EmbreeApi api) const {
  prepare(query, rays, count, api);
  trace_prepared(threads);
  answers(hits);
  prepared_.reset();
}

namespace {

// rtcBuildBVH's records, in its thread-local allocators: an inner node's
// two children with their boxes, or a leaf's indices into the bounds.
struct EmbreeBuildNode {
  bool leaf;
  unsigned count;
  RTCBounds box[2];
  const EmbreeBuildNode* child[2];
  unsigned prim[RTCL_BLOCK_WIDTH];
};

EmbreeBuildNode* new_build_node(RTCThreadLocalAllocator alloc) {
  return static_cast<EmbreeBuildNode*>(rtcThreadLocalAlloc(alloc, sizeof(EmbreeBuildNode), alignof(EmbreeBuildNode)));
}

void* create_build_node(RTCThreadLocalAllocator alloc, unsigned, void*) {
  EmbreeBuildNode* node = new_build_node(alloc);
  if (node) *node = EmbreeBuildNode{false, 0, {}, {}, {}};
  return node;
}

void set_build_children(void* node, void** children, unsigned count, void*) {
  auto* n = static_cast<EmbreeBuildNode*>(node);
  n->count = std::min(count, 2u);
  for (unsigned i = 0; i < n->count; ++i) n->child[i] = static_cast<const EmbreeBuildNode*>(children[i]);
}

void set_build_bounds(void* node, const RTCBounds** bounds, unsigned count, void*) {
  auto* n = static_cast<EmbreeBuildNode*>(node);
  for (unsigned i = 0; i < std::min(count, 2u); ++i) n->box[i] = *bounds[i];
}

void* create_build_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, std::size_t count, void*) {
  EmbreeBuildNode* leaf = new_build_node(alloc);
  if (!leaf || count > RTCL_BLOCK_WIDTH) return nullptr;
  *leaf = EmbreeBuildNode{true, static_cast<unsigned>(count), {}, {}, {}};
  for (std::size_t i = 0; i < count; ++i) leaf->prim[i] = prims[i].primID;
  return leaf;
}

Aabb to_aabb(const RTCBounds& b) { return {{b.lower_x, b.lower_y, b.lower_z}, {b.upper_x, b.upper_y, b.upper_z}}; }

// Appends the subtree of `node` (box `box`) to `tree`; returns its index.
std::uint32_t append_build_node(const EmbreeBuildNode* node, const Aabb& box, std::span<const std::uint32_t> ids,
                                BuildTree& tree) {
  if (!node || (!node->leaf && node->count != 2)) throw Error("Embree: rtcBuildBVH returned an incomplete tree");
  auto index = static_cast<std::uint32_t>(tree.nodes.size());
  tree.nodes.emplace_back();
  tree.nodes[index].bounds = box;
  if (node->leaf) {
    tree.nodes[index].first = static_cast<std::uint32_t>(tree.prims.size());
    tree.nodes[index].count = node->count;
    for (unsigned i = 0; i < node->count; ++i) tree.prims.push_back(ids[node->prim[i]]);
    return index;
  }
  std::uint32_t left = append_build_node(node->child[0], to_aabb(node->box[0]), ids, tree);
  std::uint32_t right = append_build_node(node->child[1], to_aabb(node->box[1]), ids, tree);
  tree.nodes[index].child[0] = left;
  tree.nodes[index].child[1] = right;
  return index;
}

}  // namespace

BuildTree embree_binary_tree(std::span<const Aabb> bounds, std::span<const std::uint32_t> ids, unsigned threads) {
  check_builder_input(bounds, ids, "embree");
  if (bounds.empty()) return {};
  RTCDevice device = embree_device(threads);
  std::vector<RTCBuildPrimitive> prims(bounds.size());
  Aabb all = bounds[0];
  for (std::size_t i = 0; i < bounds.size(); ++i) {
    const Aabb& b = bounds[i];
    prims[i] = {b.lower.x, b.lower.y, b.lower.z, 0u, b.upper.x, b.upper.y, b.upper.z, static_cast<unsigned>(i)};
    all.grow(b);
  }
  RTCBVH bvh = rtcNewBVH(device);
  check_embree(device, "rtcNewBVH");
  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.buildQuality = RTC_BUILD_QUALITY_MEDIUM;
  args.maxBranchingFactor = 2;
  args.maxDepth = 1024;
  args.sahBlockSize = RTCL_BLOCK_WIDTH;
  args.minLeafSize = 1;
  args.maxLeafSize = RTCL_BLOCK_WIDTH;
  args.traversalCost = 0.5f;
  args.intersectionCost = 1.0f;
  args.bvh = bvh;
  args.primitives = prims.data();
  args.primitiveCount = prims.size();
  args.primitiveArrayCapacity = prims.size();
  args.createNode = create_build_node;
  args.setNodeChildren = set_build_children;
  args.setNodeBounds = set_build_bounds;
  args.createLeaf = create_build_leaf;
  const auto* root = static_cast<const EmbreeBuildNode*>(rtcBuildBVH(&args));
  BuildTree tree;
  try {
    check_embree(device, "rtcBuildBVH");
    append_build_node(root, all, ids, tree);
  } catch (...) {
    rtcReleaseBVH(bvh);
    throw;
  }
  rtcReleaseBVH(bvh);
  return tree;
}

std::string embree_version(unsigned threads) {
  RTCDevice device = embree_device(threads);
  return std::to_string(rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION_MAJOR)) + "." +
         std::to_string(rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION_MINOR)) + "." +
         std::to_string(rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION_PATCH));
}

}  // namespace rtcl::bench

namespace rtcl::bench {

bool embree_has_packet8(unsigned threads) {
  RTCDevice device = embree_device(threads);
  return rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) != 0;
}

}  // namespace rtcl::bench
