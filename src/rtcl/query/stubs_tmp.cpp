// Temporary: the extra queries until their modules land.
#include "rtcl/accel.hpp"
#include "rtcl/error.hpp"
namespace rtcl {
void Accel::count(const Rays&, std::span<std::uint32_t>) const { throw Error("count: not yet"); }
std::vector<std::uint32_t> Accel::count(const Rays&) const { throw Error("count: not yet"); }
AllHits Accel::all_hits(const Rays&, std::uint32_t) const { throw Error("all_hits: not yet"); }
std::vector<float> Accel::signed_distance(const Points&, unsigned) const { throw Error("signed_distance: not yet"); }
std::vector<std::uint8_t> Accel::occupancy(const Points&, unsigned) const { throw Error("occupancy: not yet"); }
cl::Event Accel::count(const cl::Buffer&, const cl::Buffer&, std::size_t, const std::vector<cl::Event>&) const { throw Error("count: not yet"); }
}
