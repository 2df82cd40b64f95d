#include "rtcl/render/launch.hpp"

namespace rtcl {

cl::Event launch(const Device& device, const cl::Kernel& kernel, std::size_t count,
                 const std::vector<cl::Event>& wait) {
  return with_cl_errors([&] {
    std::size_t max_group = kernel.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(device.device());
    cl::NDRange local = max_group >= launch_group_size ? cl::NDRange(launch_group_size) : cl::NullRange;
    std::size_t global = max_group >= launch_group_size
                             ? (count + launch_group_size - 1) / launch_group_size * launch_group_size
                             : count;
    cl::Event done;
    device.queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(global), local,
                                        wait.empty() ? nullptr : &wait, &done);
    return done;
  });
}

}  // namespace rtcl
