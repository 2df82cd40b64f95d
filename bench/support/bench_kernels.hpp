// The kernels only the benchmarks run (bench/kernels/, embedded in
// rtcl_bench_support, not in librtcl); they include the library's shared
// headers ("shared/trace.h", ...) as the library's kernels do.
#pragma once

#include <string>
#include <vector>

#include "rtcl/device.hpp"
#include "rtcl/opencl.hpp"

namespace rtcl::bench {

// The program of a bench kernel file (path under bench/kernels/, e.g.
// "volume_costs.cl") built for `device` with -D `defines`, as
// Device::program builds the library's. Throws Error with the build log.
cl::Program bench_program(const Device& device, const std::string& kernel_file,
                          const std::vector<std::string>& defines = {});

}  // namespace rtcl::bench
