// Timing helpers of the bench/ programs: wall-clock milliseconds and the
// median of repeated measurements (docs/benchmarks.md quotes medians).
#pragma once
#include <algorithm>
#include <chrono>
#include <vector>

#include "rtcl/opencl.hpp"

namespace rtcl::bench {

using Clock = std::chrono::steady_clock;

// Milliseconds from `start` until now.
inline double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// The median of a non-empty set of values (the upper one of an even count).
inline double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

// Seconds a profiled command ran on the device (its event's start to end).
inline double kernel_seconds(const cl::Event& event) {
  auto start = event.getProfilingInfo<CL_PROFILING_COMMAND_START>();
  auto end = event.getProfilingInfo<CL_PROFILING_COMMAND_END>();
  return static_cast<double>(end - start) * 1e-9;
}

}  // namespace rtcl::bench
