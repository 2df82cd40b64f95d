#include "rtcl/accel.hpp"

#include <algorithm>

#include "rtcl/accel/accel_state.hpp"
#include "rtcl/accel/structure_kernels.hpp"
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
      state_(std::make_unique<State>(std::move(incoherent), config.scattered_sort)) {
  State& st = *state_;
  if (coherent) st.coherent = State::KernelSet{std::move(*coherent), {}, {}};
  const TraceKernels& single = st.incoherent.spec;
  if (single.rays_per_work_item == 1 && single.sortable && device.info().type == "cpu" &&
      config.scattered_sort != ScatteredSort::never)
    st.scattered = State::KernelSet{single, {}, {}, true};
  std::lock_guard lock(st.mutex);
  st.kernel_for(st.incoherent, Query::closest, device_, defines_);
}

Accel::~Accel() = default;

Accel::State::KernelSet& Accel::State::set_for(Coherence coherence) {
  if (coherence == Coherence::coherent && coherent) return *coherent;
  if (coherence == Coherence::scattered && scattered) return *scattered;
  return incoherent;
}

bool Accel::sorts(Coherence coherence) const { return state_->set_for(coherence).ordered; }

bool Accel::last_call_sorted() const { return state_->last_sorted; }

const cl::Event& Accel::first_event() const { return state_->first_event; }

Accel::State::QueryKernel& Accel::State::kernel_for(KernelSet& set, Query query, const Device& device_,
                                                    const std::vector<std::string>& structure_defines) {
  std::optional<QueryKernel>& slot = query == Query::closest ? set.closest : set.any;
  if (slot) return *slot;
  std::vector<std::string> defines = structure_defines;
  defines.push_back(query == Query::closest ? "RTCL_QUERY_CLOSEST" : "RTCL_QUERY_ANY");
  if (set.ordered) defines.push_back("RTCL_TRACE_ORDER");
  cl::Program program = device_.program(set.spec.file, defines);
  std::string stem = set.spec.file.substr(set.spec.file.rfind('/') + 1);
  stem = stem.substr(0, stem.rfind('.'));
  std::string kernel_name = (query == Query::closest ? "trace_closest_" : "trace_any_") + stem;
  with_cl_errors([&] { slot = QueryKernel{cl::Kernel(program, kernel_name.c_str()), false}; });
  return *slot;
}

bool Accel::State::sort_this_call(Coherence coherence, Query query) {
  if (coherence != Coherence::scattered || !scattered) return false;
  record_pending(query);
  return sort_choices[query == Query::closest ? 0 : 1].next();
}

bool Accel::sort_choice_settled(Query query) const {
  State& st = *state_;
  std::lock_guard lock(st.mutex);
  if (!st.scattered) return true;
  st.record_pending(query);
  return st.sort_choices[query == Query::closest ? 0 : 1].settled();
}

void Accel::State::record_pending(Query query) {
  std::size_t q = query == Query::closest ? 0 : 1;
  if (std::optional<PendingCall>& pending = this->pending[q]) {
    cl_int status = pending->done.getInfo<CL_EVENT_COMMAND_EXECUTION_STATUS>();
    if (status == CL_COMPLETE) {
      double ms = static_cast<double>(pending->done.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                                      pending->first.getProfilingInfo<CL_PROFILING_COMMAND_START>()) *
                  1e-6;
      sort_choices[q].record(pending->sorted, ms / static_cast<double>(pending->ray_count));
      pending.reset();
    } else if (status < 0) {
      pending.reset();  // failed: nothing to learn from it
    }
  }
}

std::size_t Accel::rays_per_work_item(Coherence coherence) const {
  return state_->set_for(coherence).spec.rays_per_work_item;
}

std::size_t Accel::occluder_run(Coherence coherence) const { return state_->set_for(coherence).spec.occluder_run; }

cl::Event Accel::trace(Query query, const cl::Buffer& rays, const cl::Buffer& hits, std::size_t ray_count,
                       const std::vector<cl::Event>& wait, Coherence coherence) const {
  std::lock_guard lock(state_->mutex);
  return trace_locked(query, rays, hits, ray_count, wait, coherence);
}

cl::Event Accel::trace_locked(Query query, const cl::Buffer& rays, const cl::Buffer& hits, std::size_t ray_count,
                              const std::vector<cl::Event>& wait, Coherence coherence) const {
  State& st = *state_;
  return with_cl_errors([&] {
    if (ray_count > 0xffffffffu) throw Error(name_ + " trace: ray_count " + std::to_string(ray_count) + " exceeds 2^32-1");
    std::size_t ray_bytes = rays.getInfo<CL_MEM_SIZE>(), hit_bytes = hits.getInfo<CL_MEM_SIZE>();
    if (ray_bytes < ray_count * sizeof(Ray))
      throw Error(name_ + " trace: ray buffer holds " + std::to_string(ray_bytes / sizeof(Ray)) + " rays, " +
                  std::to_string(ray_count) + " requested");
    if (hit_bytes < ray_count * sizeof(Hit))
      throw Error(name_ + " trace: hit buffer holds " + std::to_string(hit_bytes / sizeof(Hit)) + " hits, " +
                  std::to_string(ray_count) + " requested");
    bool sorted = ray_count > 0 && st.sort_this_call(coherence, query);
    State::KernelSet& set =
        sorted ? *st.scattered : st.set_for(coherence == Coherence::scattered ? Coherence::incoherent : coherence);
    State::QueryKernel& slot = st.kernel_for(set, query, device_, defines_);
    st.last_sorted = sorted;
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
      st.first_event = done;
      return done;
    }
    std::vector<cl::Event> before = wait;
    if (set.ordered) {
      if (!st.sort) st.sort = std::make_unique<RaySort>(device_, stats_.bounds);
      std::vector<cl::Event> passes = st.sort->enqueue(rays, ray_count, wait);
      kernel.setArg(3, st.sort->order());
      before = {passes.back()};
      st.first_event = passes.front();
    }
    const TraceKernels& spec = set.spec;
    std::size_t per_item = spec.rays_per_work_item * (query == Query::any ? spec.occluder_run : 1);
    done = detail::AccelAccess::launch(*this, kernel, (ray_count + per_item - 1) / per_item, before);
    if (!set.ordered) st.first_event = done;
    std::size_t q = query == Query::closest ? 0 : 1;
    if (coherence == Coherence::scattered && st.scattered && device_.profiling() && !st.pending[q] && slot.launches > 0)
      st.pending[q] = State::PendingCall{sorted, st.first_event, done, ray_count};
    ++slot.launches;
    return done;
  });
}

double Accel::last_call_ms(const cl::Event& done) const {
  return with_cl_errors([&] {
    done.wait();
    return static_cast<double>(done.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                               state_->first_event.getProfilingInfo<CL_PROFILING_COMMAND_START>()) *
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

const OptionSpec& occluder_run_option() {
  static const OptionSpec spec{"occluder_run", OptionType::integer, std::int64_t{0}, 0, 1024, false,
          "occlusion queries: rays (packets of 8 in a packet kernel) per work-item, each tested first against the "
          "leaf that blocked the previous one (1 = no such test; 0 = " + std::to_string(kCpuOccluderRun) +
          " on CPU devices, 1 on others)"};
  return spec;
}

std::vector<std::string> primitive_defines(const Geometry& geometry) {
  std::vector<std::string> defines;
  if (!geometry.spheres.empty()) defines.push_back("RTCL_HAS_SPHERES");
  return defines;
}

}  // namespace rtcl

namespace rtcl::detail {

cl::Kernel& AccelAccess::kernel(const Accel& accel, const std::string& file, const std::string& kernel_name,
                                const std::vector<std::string>& defines, cl_uint first_structure_arg,
                                std::optional<Precision> level) {
  std::string key = file + ":" + kernel_name;
  if (level) key += " @" + std::string(precision_name(*level));
  for (const std::string& define : defines) key += " " + define;
  auto& kernels = accel.state_->query_kernels;
  if (auto found = kernels.find(key); found != kernels.end()) return found->second;
  std::vector<std::string> all = accel.defines_;
  if (level && *level != accel.precision_) {
    // defines_ ends with the structure level's options (with_precision)
    const std::vector<std::string> own = precision_build_options(accel.precision_);
    std::erase_if(all, [&](const std::string& d) { return std::find(own.begin(), own.end(), d) != own.end(); });
    for (std::string& d : precision_build_options(*level)) all.push_back(std::move(d));
  }
  all.insert(all.end(), defines.begin(), defines.end());
  cl::Program program = accel.device_.program(file, all);
  return with_cl_errors([&]() -> cl::Kernel& {
    cl::Kernel kernel(program, kernel_name.c_str());
    accel.set_structure_args(kernel, first_structure_arg);
    return kernels.emplace(key, std::move(kernel)).first->second;
  });
}

void AccelAccess::require_plain_bvh8(const Accel& accel, const char* call) {
  if (accel.plain_bvh8()) return;
  throw Error(std::string(call) + ": structure " + accel.name() +
              " does not support this query (supported: bvh, bvh-ploc, bvh-packet)");
}

cl::Event AccelAccess::launch(const Accel& accel, const cl::Kernel& kernel, std::size_t items,
                              const std::vector<cl::Event>& wait) {
  return launch_items(accel.device_, kernel, items, wait);
}

cl::Event launch_items(const Device& device, const cl::Kernel& kernel, std::size_t items,
                       const std::vector<cl::Event>& wait) {
  constexpr std::size_t kGroup = 64;
  cl::Event done;
  if (items == 0) {
    device.queue().enqueueMarkerWithWaitList(&wait, &done);
    return done;
  }
  const bool fixed = kernel.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(device.device()) >= kGroup;
  const std::size_t global = fixed ? (items + kGroup - 1) / kGroup * kGroup : items;
  device.queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(global),
                                      fixed ? cl::NDRange(kGroup) : cl::NullRange,
                                      wait.empty() ? nullptr : &wait, &done);
  return done;
}

}  // namespace rtcl::detail
