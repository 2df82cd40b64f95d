// Temporary: the extra queries until their modules land.
#include "rtcl/accel.hpp"
#include "rtcl/error.hpp"
namespace rtcl {
void Accel::closest_points(const Points&, std::span<PointHit>, float) const { throw Error("closest_points: not yet"); }
std::vector<PointHit> Accel::closest_points(const Points&, float) const { throw Error("closest_points: not yet"); }
std::vector<float> Accel::distance(const Points&) const { throw Error("distance: not yet"); }
cl::Event Accel::closest_points(const cl::Buffer&, const cl::Buffer&, std::size_t, float, const std::vector<cl::Event>&) const { throw Error("closest_points: not yet"); }
}
