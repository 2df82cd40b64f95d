// Temporary: the extra queries until their modules land.
#include "rtcl/accel.hpp"
#include "rtcl/error.hpp"
namespace rtcl {
void Accel::count(const Rays&, std::span<std::uint32_t>) const { throw Error("count: not yet"); }
std::vector<std::uint32_t> Accel::count(const Rays&) const { throw Error("count: not yet"); }
AllHits Accel::all_hits(const Rays&, std::uint32_t) const { throw Error("all_hits: not yet"); }
void Accel::closest_points(const Points&, std::span<PointHit>, float) const { throw Error("closest_points: not yet"); }
std::vector<PointHit> Accel::closest_points(const Points&, float) const { throw Error("closest_points: not yet"); }
std::vector<float> Accel::distance(const Points&) const { throw Error("distance: not yet"); }
cl::Event Accel::count(const cl::Buffer&, const cl::Buffer&, std::size_t, const std::vector<cl::Event>&) const { throw Error("count: not yet"); }
cl::Event Accel::closest_points(const cl::Buffer&, const cl::Buffer&, std::size_t, float, const std::vector<cl::Event>&) const { throw Error("closest_points: not yet"); }
}
