#include "rtcl/accel/accel.hpp"

#include "rtcl/layouts.hpp"

namespace rtcl {

Accel::Accel(const Device& device, std::string name, TraceKernels incoherent, std::optional<TraceKernels> coherent,
             std::vector<std::string> defines, AccelStats stats)
    : device_(device),
      name_(std::move(name)),
      stats_(stats),
      defines_(std::move(defines)),
      coherent_spec_(std::move(coherent)),
      incoherent_(make_kernels(incoherent)) {}

Accel::KernelSet Accel::make_kernels(const TraceKernels& kernels) const {
  cl::Program program = device_.program(kernels.file, defines_);
  std::string stem = kernels.file.substr(kernels.file.rfind('/') + 1);
  stem = stem.substr(0, stem.rfind('.'));
  KernelSet set;
  set.rays_per_work_item = kernels.rays_per_work_item;
  with_cl_errors([&] {
    set.closest = cl::Kernel(program, ("trace_closest_" + stem).c_str());
    set.any = cl::Kernel(program, ("trace_any_" + stem).c_str());
  });
  return set;
}

Accel::KernelSet& Accel::kernels_for(Coherence coherence) const {
  if (coherence == Coherence::incoherent || !coherent_spec_) return incoherent_;
  if (!coherent_) coherent_ = make_kernels(*coherent_spec_);
  return *coherent_;
}

std::size_t Accel::rays_per_work_item(Coherence coherence) const {
  if (coherence == Coherence::coherent && coherent_spec_) return coherent_spec_->rays_per_work_item;
  return incoherent_.rays_per_work_item;
}

cl::Event Accel::trace(Query query, const cl::Buffer& rays, const cl::Buffer& hits, std::size_t ray_count,
                       const std::vector<cl::Event>& wait, Coherence coherence) const {
  return with_cl_errors([&] {
    if (ray_count > 0xffffffffu) throw Error(name_ + " trace: ray_count " + std::to_string(ray_count) + " exceeds 2^32-1");
    std::size_t ray_bytes = rays.getInfo<CL_MEM_SIZE>(), hit_bytes = hits.getInfo<CL_MEM_SIZE>();
    if (ray_bytes < ray_count * sizeof(Ray))
      throw Error(name_ + " trace: ray buffer holds " + std::to_string(ray_bytes / sizeof(Ray)) + " rays, " +
                  std::to_string(ray_count) + " requested");
    if (hit_bytes < ray_count * sizeof(Hit))
      throw Error(name_ + " trace: hit buffer holds " + std::to_string(hit_bytes / sizeof(Hit)) + " hits, " +
                  std::to_string(ray_count) + " requested");
    KernelSet& set = kernels_for(coherence);
    if (!set.args_set) {  // not in make_kernels: the constructor runs before the structure exists
      set_structure_args(set.closest, 3);
      set_structure_args(set.any, 3);
      set.args_set = true;
    }
    cl::Kernel& kernel = query == Query::closest ? set.closest : set.any;
    kernel.setArg(0, rays);
    kernel.setArg(1, hits);
    kernel.setArg(2, static_cast<cl_uint>(ray_count));
    cl::Event done;
    if (ray_count == 0) {
      device_.queue().enqueueMarkerWithWaitList(&wait, &done);
      return done;
    }
    // A fixed work-group size (global rounded up; the kernels check ray_count):
    // PoCL generates code per local size, and left to choose (NULL) it picks
    // one per global size, so each new ray count would cost a code generation.
    const std::size_t group = 64;
    bool fixed = kernel.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(device_.device()) >= group;
    std::size_t items = (ray_count + set.rays_per_work_item - 1) / set.rays_per_work_item;
    std::size_t global = fixed ? (items + group - 1) / group * group : items;
    device_.queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(global),
                                         fixed ? cl::NDRange(group) : cl::NullRange,
                                         wait.empty() ? nullptr : &wait, &done);
    return done;
  });
}

cl::Event Accel::trace(Query query, cl_mem rays, cl_mem hits, std::size_t ray_count,
                       const std::vector<cl::Event>& wait, Coherence coherence) const {
  if (!rays || !hits) throw Error(name_ + " trace: null ray or hit buffer");
  return with_cl_errors(
      [&] { return trace(query, cl::Buffer(rays, true), cl::Buffer(hits, true), ray_count, wait, coherence); });
}

std::vector<std::string> primitive_defines(const Geometry& geometry) {
  std::vector<std::string> defines;
  if (!geometry.spheres.empty()) defines.push_back("RTCL_HAS_SPHERES");
  return defines;
}

}  // namespace rtcl
