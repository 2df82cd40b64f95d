#include "bench/support/embree_instances.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <string>
#include <thread>

#include "bench/support/timing.hpp"
#include "rtcl/error.hpp"

namespace rtcl::bench {

struct EmbreeInstances::Impl {
  RTCDevice device = nullptr;
  RTCScene child = nullptr, top = nullptr;
  unsigned threads = 1;
};

EmbreeInstances::EmbreeInstances(const Geometry& mesh, unsigned threads) : impl_(std::make_unique<Impl>()) {
  impl_->threads = std::max(1u, threads);
  const std::string config = "threads=" + std::to_string(impl_->threads);
  impl_->device = rtcNewDevice(config.c_str());
  if (!impl_->device) throw Error("Embree: rtcNewDevice(\"" + config + "\") failed");
  impl_->child = rtcNewScene(impl_->device);
  RTCGeometry g = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, mesh.vertices.data(), 0,
                             sizeof(glm::vec3), mesh.vertices.size());
  rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh.triangles.data(), 0,
                             sizeof(glm::uvec3), mesh.triangles.size());
  rtcCommitGeometry(g);
  rtcAttachGeometry(impl_->child, g);
  rtcReleaseGeometry(g);
  auto start = Clock::now();
  rtcCommitScene(impl_->child);
  child_ms_ = ms_since(start);
}

EmbreeInstances::~EmbreeInstances() {
  if (impl_->top) rtcReleaseScene(impl_->top);
  rtcReleaseScene(impl_->child);
  rtcReleaseDevice(impl_->device);
}

std::pair<double, double> EmbreeInstances::place(const std::vector<Transform>& placements) {
  if (impl_->top) rtcReleaseScene(impl_->top);
  auto start = Clock::now();
  impl_->top = rtcNewScene(impl_->device);
  for (std::size_t k = 0; k < placements.size(); ++k) {
    RTCGeometry g = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(g, impl_->child);
    rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, &placements[k].m[0][0]);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(impl_->top, g, static_cast<unsigned>(k));
    rtcReleaseGeometry(g);
  }
  const double setup = ms_since(start);
  start = Clock::now();
  rtcCommitScene(impl_->top);
  return {setup, ms_since(start)};
}

double EmbreeInstances::trace(const std::vector<Ray>& rays, std::vector<InstanceHit>* hits) const {
  if (!impl_->top) throw Error("EmbreeInstances::trace: no placements (place() first)");
  std::vector<RTCRayHit> records(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Ray& r = rays[i];
    RTCRayHit& h = records[i];
    h.ray.org_x = r.ox, h.ray.org_y = r.oy, h.ray.org_z = r.oz;
    h.ray.dir_x = r.dx, h.ray.dir_y = r.dy, h.ray.dir_z = r.dz;
    h.ray.tnear = r.tmin;
    h.ray.tfar = r.tmax;
    h.ray.time = 0.0f;
    h.ray.mask = ~0u;
    h.ray.id = 0;
    h.ray.flags = 0;
    h.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    h.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  }
  std::atomic<std::size_t> next{0};
  constexpr std::size_t kBlock = 4096;
  RTCScene top = impl_->top;
  auto work = [&] {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (std::size_t begin; (begin = next.fetch_add(kBlock)) < records.size();)
      for (std::size_t i = begin; i < std::min(begin + kBlock, records.size()); ++i)
        rtcIntersect1(top, &context, &records[i]);
  };
  auto start = Clock::now();
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < impl_->threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  const double ms = ms_since(start);
  if (hits) {
    hits->resize(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const bool hit = records[i].hit.geomID != RTC_INVALID_GEOMETRY_ID;
      (*hits)[i] = {hit ? records[i].hit.instID[0] : 0u, hit ? static_cast<std::int32_t>(records[i].hit.primID) : -1};
    }
  }
  return ms;
}

}  // namespace rtcl::bench
