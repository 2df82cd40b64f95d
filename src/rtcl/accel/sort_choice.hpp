// Whether a Coherence::scattered trace call sorts its rays on the device
// first (RaySort) or traces them in the caller's order: the sort pays where
// a ray visits many nodes and costs where rays are cheap
// (docs/structures.md), which only the calls themselves show. So, by
// default, an Accel measures: per query kind, the device time per ray
// of its finished scattered calls, sorted and not (not the first launch of
// either way's kernel, whose time includes PoCL's code generation), and
// sorts when sorting measured faster.
#pragma once

#include <array>
#include <cstdint>

#include "rtcl/accel.hpp"

namespace rtcl {


class SortChoice {
 public:
  // Every kExplorePeriod-th choice once both ways are measured takes the
  // slower one, so that its time follows the rays the calls now bring.
  static constexpr int kExplorePeriod = 16;
  // Calls measured each way before the choice is made (one launch's time
  // varies by up to a fifth on a busy host).
  static constexpr std::uint64_t kFirstMeasurements = 2;

  explicit SortChoice(ScatteredSort policy = ScatteredSort::measured) : policy_(policy) {}

  // Whether the next call sorts. Measured: sorts until kFirstMeasurements
  // sorted calls are measured, then does not until as many unsorted ones
  // are, then takes the way with the lower time per ray (ties: sorted), but
  // the other on every kExplorePeriod-th call.
  bool next();
  // A finished call's device time per ray (ms > 0); the time kept for its
  // way is the mean of its first kFirstMeasurements, then the mean of the
  // time kept and this one.
  void record(bool sorted, double ms_per_ray);

  // The time per ray kept for each way (0 until one is recorded).
  double ms_per_ray(bool sorted) const { return ms_per_ray_[sorted]; }
  // Whether next() now answers from measurements (or from the policy).
  bool settled() const {
    return policy_ != ScatteredSort::measured ||
           (measured_[0] >= kFirstMeasurements && measured_[1] >= kFirstMeasurements);
  }

 private:
  ScatteredSort policy_;
  std::array<double, 2> ms_per_ray_{};   // [0] unsorted, [1] sorted
  std::array<std::uint64_t, 2> measured_{};
  int since_explore_ = 0;
};

}  // namespace rtcl
