#include "bench/support/bench_kernels.hpp"

#include <map>
#include <string_view>

#include "rtcl/cl/program.hpp"
#include "rtcl/error.hpp"

namespace rtcl {
// Generated at build time from bench/kernels/ (cmake/embed_kernels.cmake).
const std::map<std::string_view, std::string_view>& embedded_bench_kernels();
}  // namespace rtcl

namespace rtcl::bench {

cl::Program bench_program(const Device& device, const std::string& kernel_file,
                          const std::vector<std::string>& defines) {
  const auto& table = embedded_bench_kernels();
  auto it = table.find(kernel_file);
  if (it == table.end()) throw Error("bench kernel file " + kernel_file + ": not embedded (bench/kernels/)");
  std::string source = kernel_source("bench/" + kernel_file, std::string(it->second));
  std::string options = "-cl-std=CL1.2";
  if (device.info().fp64) options += " -DRTCL_HAS_FP64";
  for (const auto& d : defines) options += (d.rfind("-cl-", 0) == 0 ? " " : " -D") + d;
  cl::Program program(device.context(), source);
  try {
    program.build(std::vector<cl::Device>{device.device()}, options.c_str());
  } catch (const cl::Error&) {
    std::string log = program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device.device());
    throw Error("building bench kernel file " + kernel_file + " (options: " + options + ") failed on " +
                device.info().name + ":\n" + name_source_lines(log, source));
  }
  return program;
}

}  // namespace rtcl::bench
