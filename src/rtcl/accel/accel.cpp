#include "rtcl/accel/accel.hpp"

#include "rtcl/layouts.hpp"

namespace rtcl {

namespace {

std::vector<std::string> with_precision(const DeviceInfo& device, std::vector<std::string> defines,
                                        Precision precision) {
  require_precision(device, precision);
  for (std::string& option : precision_build_options(precision)) defines.push_back(std::move(option));
  return defines;
}

}  // namespace

Accel::Accel(const Device& device, std::string name, TraceKernels incoherent, std::optional<TraceKernels> coherent,
             std::vector<std::string> defines, AccelStats stats, const AccelConfig& config)
    : device_(device),
      name_(std::move(name)),
      stats_(stats),
      precision_(config.precision),
      defines_(with_precision(device.info(), std::move(defines), config.precision)),
      incoherent_{std::move(incoherent), {}, {}},
      sort_choices_{SortChoice(config.scattered_sort), SortChoice(config.scattered_sort)} {
  if (coherent) coherent_ = KernelSet{std::move(*coherent), {}, {}};
  const TraceKernels& single = incoherent_.spec;
  if (single.rays_per_work_item == 1 && single.sortable && device.info().type == "cpu" &&
      config.scattered_sort != ScatteredSort::never)
    scattered_ = KernelSet{single, {}, {}, true};
  kernel_for(incoherent_, Query::closest);
}

Accel::KernelSet& Accel::set_for(Coherence coherence) const {
  if (coherence == Coherence::coherent && coherent_) return *coherent_;
  if (coherence == Coherence::scattered && scattered_) return *scattered_;
  return incoherent_;
}

bool Accel::sorts(Coherence coherence) const { return set_for(coherence).ordered; }

Accel::QueryKernel& Accel::kernel_for(KernelSet& set, Query query) const {
  std::optional<QueryKernel>& slot = query == Query::closest ? set.closest : set.any;
  if (slot) return *slot;
  std::vector<std::string> defines = defines_;
  defines.push_back(query == Query::closest ? "RTCL_QUERY_CLOSEST" : "RTCL_QUERY_ANY");
  if (set.ordered) defines.push_back("RTCL_TRACE_ORDER");
  cl::Program program = device_.program(set.spec.file, defines);
  std::string stem = set.spec.file.substr(set.spec.file.rfind('/') + 1);
  stem = stem.substr(0, stem.rfind('.'));
  std::string kernel_name = (query == Query::closest ? "trace_closest_" : "trace_any_") + stem;
  with_cl_errors([&] { slot = QueryKernel{cl::Kernel(program, kernel_name.c_str()), false}; });
  return *slot;
}

bool Accel::sort_this_call(Coherence coherence, Query query) const {
  if (coherence != Coherence::scattered || !scattered_) return false;
  record_pending(query);
  return sort_choices_[query == Query::closest ? 0 : 1].next();
}

bool Accel::sort_choice_settled(Query query) const {
  if (!scattered_) return true;
  record_pending(query);
  return sort_choices_[query == Query::closest ? 0 : 1].settled();
}

void Accel::record_pending(Query query) const {
  std::size_t q = query == Query::closest ? 0 : 1;
  if (std::optional<PendingCall>& pending = pending_[q]) {
    cl_int status = pending->done.getInfo<CL_EVENT_COMMAND_EXECUTION_STATUS>();
    if (status == CL_COMPLETE) {
      double ms = static_cast<double>(pending->done.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                                      pending->first.getProfilingInfo<CL_PROFILING_COMMAND_START>()) *
                  1e-6;
      sort_choices_[q].record(pending->sorted, ms / static_cast<double>(pending->ray_count));
      pending.reset();
    } else if (status < 0) {
      pending.reset();  // failed: nothing to learn from it
    }
  }
}

std::size_t Accel::rays_per_work_item(Coherence coherence) const { return set_for(coherence).spec.rays_per_work_item; }

std::size_t Accel::occluder_run(Coherence coherence) const { return set_for(coherence).spec.occluder_run; }

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
    bool sorted = ray_count > 0 && sort_this_call(coherence, query);
    KernelSet& set = sorted ? *scattered_ : set_for(coherence == Coherence::scattered ? Coherence::incoherent : coherence);
    QueryKernel& slot = kernel_for(set, query);
    last_sorted_ = sorted;
    if (!slot.args_set) {
      set_structure_args(slot.kernel, set.ordered ? 4 : 3);
      slot.args_set = true;
    }
    cl::Kernel& kernel = slot.kernel;
    set_call_args(kernel);
    kernel.setArg(0, rays);
    kernel.setArg(1, hits);
    kernel.setArg(2, static_cast<cl_uint>(ray_count));
    cl::Event done;
    if (ray_count == 0) {
      device_.queue().enqueueMarkerWithWaitList(&wait, &done);
      first_event_ = done;
      return done;
    }
    std::vector<cl::Event> before = wait;
    if (set.ordered) {
      if (!sort_) sort_ = std::make_unique<RaySort>(device_, stats_.bounds);
      std::vector<cl::Event> passes = sort_->enqueue(rays, ray_count, wait);
      kernel.setArg(3, sort_->order());
      before = {passes.back()};
      first_event_ = passes.front();
    }
    // A fixed work-group size (global rounded up; the kernels check ray_count):
    // PoCL generates code per local size, and left to choose (NULL) it picks
    // one per global size, so each new ray count would cost a code generation.
    const std::size_t group = 64;
    bool fixed = kernel.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(device_.device()) >= group;
    const TraceKernels& spec = set.spec;
    std::size_t per_item = spec.rays_per_work_item * (query == Query::any ? spec.occluder_run : 1);
    std::size_t items = (ray_count + per_item - 1) / per_item;
    std::size_t global = fixed ? (items + group - 1) / group * group : items;
    device_.queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(global),
                                         fixed ? cl::NDRange(group) : cl::NullRange,
                                         before.empty() ? nullptr : &before, &done);
    if (!set.ordered) first_event_ = done;
    std::size_t q = query == Query::closest ? 0 : 1;
    if (coherence == Coherence::scattered && scattered_ && device_.profiling() && !pending_[q] && slot.launches > 0)
      pending_[q] = PendingCall{sorted, first_event_, done, ray_count};
    ++slot.launches;
    return done;
  });
}

double Accel::last_call_ms(const cl::Event& done) const {
  return with_cl_errors([&] {
    done.wait();
    return static_cast<double>(done.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                               first_event_.getProfilingInfo<CL_PROFILING_COMMAND_START>()) *
           1e-6;
  });
}

cl::Event Accel::trace(Query query, cl_mem rays, cl_mem hits, std::size_t ray_count,
                       const std::vector<cl::Event>& wait, Coherence coherence) const {
  if (!rays || !hits) throw Error(name_ + " trace: null ray or hit buffer");
  return with_cl_errors(
      [&] { return trace(query, cl::Buffer(rays, true), cl::Buffer(hits, true), ray_count, wait, coherence); });
}

std::size_t occluder_run_for(std::uint32_t requested, const DeviceInfo& device) {
  if (requested > 0) return requested;
  return device.type == "cpu" ? kCpuOccluderRun : 1;
}

bool packets_for_coherent_calls(const DeviceInfo& device) { return device.type == "cpu"; }

OptionSpec occluder_run_option() {
  return {"occluder_run", OptionType::integer, std::int64_t{0}, 0, 1024, false,
          "occlusion queries: rays (packets of 8 in a packet kernel) per work-item, each tested first against the "
          "leaf that blocked the previous one (1 = no such test; 0 = 16 on CPU devices, 1 on others)"};
}

std::vector<std::string> primitive_defines(const Geometry& geometry) {
  std::vector<std::string> defines;
  if (!geometry.spheres.empty()) defines.push_back("RTCL_HAS_SPHERES");
  return defines;
}

}  // namespace rtcl
