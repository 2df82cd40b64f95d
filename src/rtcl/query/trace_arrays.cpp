// Accel's closest- and any-hit queries on host arrays (rtcl/accel.hpp):
// batches through HostBatches, each traced by the cl::Buffer path.
#include <mutex>
#include <string>

#include "rtcl/accel.hpp"
#include "rtcl/accel/accel_state.hpp"
#include "rtcl/error.hpp"
#include "rtcl/query/host_batches.hpp"

namespace rtcl {

void Accel::trace(Query query, const Rays& rays, std::span<Hit> hits, Coherence coherence) const {
  const char* call = query == Query::closest ? "intersect" : "occluded";
  if (hits.size() != rays.size())
    throw Error(std::string(call) + ": hits holds " + std::to_string(hits.size()) + " records for " +
                std::to_string(rays.size()) + " rays");
  if (rays.size() > 0 && !hits.data()) throw Error(std::string(call) + ": null hits array");
  HostBatches batches(device_, rays.size(), sizeof(Ray), sizeof(Hit));
  std::lock_guard lock(state_->mutex);
  run_rays(
      batches, rays, state_->staging,
      [&](const cl::Buffer& in, const cl::Buffer& out, std::size_t n, const std::vector<cl::Event>& wait) {
        return trace_locked(query, in, out, n, wait, coherence);
      },
      hits.data());
}

std::vector<Hit> Accel::intersect(const Rays& rays, Coherence coherence) const {
  std::vector<Hit> hits(rays.size());
  trace(Query::closest, rays, hits, coherence);
  return hits;
}

std::vector<std::uint8_t> Accel::occluded(const Rays& rays, Coherence coherence) const {
  std::vector<Hit> hits(rays.size());
  trace(Query::any, rays, hits, coherence);
  std::vector<std::uint8_t> blocked(rays.size());
  for (std::size_t i = 0; i < hits.size(); ++i) blocked[i] = hits[i].prim >= 0 ? 1 : 0;
  return blocked;
}

}  // namespace rtcl
