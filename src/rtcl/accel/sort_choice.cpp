#include "rtcl/accel/sort_choice.hpp"

namespace rtcl {

bool SortChoice::next() {
  if (policy_ != ScatteredSort::measured) return policy_ == ScatteredSort::always;
  if (measured_[1] < kFirstMeasurements) return true;
  if (measured_[0] < kFirstMeasurements) return false;
  bool faster = ms_per_ray_[1] <= ms_per_ray_[0];
  if (++since_explore_ >= kExplorePeriod) {
    since_explore_ = 0;
    return !faster;
  }
  return faster;
}

void SortChoice::record(bool sorted, double ms_per_ray) {
  if (!(ms_per_ray > 0.0)) return;
  double& kept = ms_per_ray_[sorted];
  std::uint64_t n = ++measured_[sorted];
  kept = n <= kFirstMeasurements ? kept + (ms_per_ray - kept) / static_cast<double>(n) : 0.5 * (kept + ms_per_ray);
}

}  // namespace rtcl
