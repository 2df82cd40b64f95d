#include "rtcl/device.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cctype>
#include <cstdlib>
#include <functional>
#include <map>
#include <mutex>
#include <thread>
#include <tuple>

#include "rtcl/cl/device_limits.hpp"
#include "rtcl/cl/program.hpp"
#include "rtcl/error.hpp"

namespace rtcl {

struct Device::State {
  DeviceInfo info;
  cl::Context context;
  cl::Device device;
  mutable cl::CommandQueue queue;
  bool profiling = false;
  mutable std::mutex cache_mutex;
  // key: source hash, options
  mutable std::map<std::tuple<std::size_t, std::string>, cl::Program> programs;
  // Bytes of the buffers allocated through this device that are still alive
  // (decremented by each buffer's OpenCL destructor callback, which may run
  // after the Device is gone, hence shared).
  std::shared_ptr<std::atomic<std::size_t>> live_bytes = std::make_shared<std::atomic<std::size_t>>(0);
};

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == '\0' || std::isspace(static_cast<unsigned char>(s.back())))) s.pop_back();
  return s;
}

DeviceInfo describe(const cl::Platform& platform, const cl::Device& device, std::size_t index) {
  DeviceInfo info;
  info.index = index;
  info.platform = trim(platform.getInfo<CL_PLATFORM_NAME>());
  info.name = trim(device.getInfo<CL_DEVICE_NAME>());
  auto type = device.getInfo<CL_DEVICE_TYPE>();
  info.type = (type & CL_DEVICE_TYPE_GPU)           ? "gpu"
              : (type & CL_DEVICE_TYPE_CPU)         ? "cpu"
              : (type & CL_DEVICE_TYPE_ACCELERATOR) ? "accelerator"
                                                    : "other";
  info.version = trim(device.getInfo<CL_DEVICE_VERSION>());
  info.compute_units = device.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
  DeviceLimits limits = limits_with_overrides(
      {device.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>(), device.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>()});
  info.global_mem_bytes = limits.global_mem_bytes;
  info.max_alloc_bytes = limits.max_alloc_bytes;
  info.fp64 = device.getInfo<CL_DEVICE_EXTENSIONS>().find("cl_khr_fp64") != std::string::npos;
  return info;
}

std::vector<std::pair<cl::Platform, cl::Device>> all_devices() {
  std::vector<std::pair<cl::Platform, cl::Device>> out;
  std::vector<cl::Platform> platforms;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error&) {
    return out;  // ocl-icd: no platform installed (CL_PLATFORM_NOT_FOUND_KHR)
  }
  for (auto& p : platforms) {
    std::vector<cl::Device> devices;
    try {
      p.getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error&) {
      continue;  // a platform without devices
    }
    for (auto& d : devices) out.emplace_back(p, d);
  }
  return out;
}

}  // namespace

std::vector<DeviceInfo> list_devices() {
  return with_cl_errors([] {
    std::vector<DeviceInfo> out;
    auto devices = all_devices();
    for (std::size_t i = 0; i < devices.size(); ++i) out.push_back(describe(devices[i].first, devices[i].second, i));
    return out;
  });
}

Device::Device(std::shared_ptr<State> state) : state_(std::move(state)) {}

Device Device::open(std::string_view selector_in) {
  return with_cl_errors([&] {
    std::string selector(selector_in);
    std::string origin = "Device::open selector";
    if (selector.empty()) {
      if (const char* env = std::getenv("RTCL_DEVICE"); env && *env) {
        selector = env;
        origin = "RTCL_DEVICE";
      }
    }
    auto devices = all_devices();
    if (devices.empty())
      throw Error("no OpenCL device found: install an OpenCL driver (on Debian: apt-get install pocl-opencl-icd) "
                  "and check with `rtcl devices`");
    std::size_t chosen = devices.size();
    if (selector.empty()) {
      chosen = 0;
    } else if (std::all_of(selector.begin(), selector.end(), [](unsigned char c) { return std::isdigit(c); })) {
      chosen = std::stoul(selector);
      if (chosen >= devices.size())
        throw Error(origin + " \"" + selector + "\": no such device (there are " + std::to_string(devices.size()) +
                    "; see `rtcl devices`)");
    } else {
      for (std::size_t i = 0; i < devices.size() && chosen == devices.size(); ++i) {
        auto info = describe(devices[i].first, devices[i].second, i);
        if (lower(info.platform + " " + info.name).find(lower(selector)) != std::string::npos) chosen = i;
      }
      if (chosen == devices.size())
        throw Error(origin + " \"" + selector + "\": no device name matches (see `rtcl devices`)");
    }
    auto state = std::make_shared<State>();
    state->info = describe(devices[chosen].first, devices[chosen].second, chosen);
    state->device = devices[chosen].second;
    state->context = cl::Context(state->device);
    state->queue = cl::CommandQueue(state->context, state->device, CL_QUEUE_PROFILING_ENABLE);
    state->profiling = true;
    return Device(std::move(state));
  });
}

Device Device::adopt(cl_context context, cl_device_id device, cl_command_queue queue) {
  return with_cl_errors([&] {
    if (!context || !device || !queue) throw Error("Device::adopt: context, device and queue must not be null");
    auto state = std::make_shared<State>();
    state->context = cl::Context(context, true);
    state->device = cl::Device(device, true);
    state->queue = cl::CommandQueue(queue, true);
    state->profiling = (state->queue.getInfo<CL_QUEUE_PROPERTIES>() & CL_QUEUE_PROFILING_ENABLE) != 0;
    cl::Platform platform(state->device.getInfo<CL_DEVICE_PLATFORM>(), true);
    std::size_t index = 0;
    auto devices = all_devices();
    for (std::size_t i = 0; i < devices.size(); ++i)
      if (devices[i].second() == device) index = i;
    state->info = describe(platform, state->device, index);
    return Device(std::move(state));
  });
}

const DeviceInfo& Device::info() const { return state_->info; }
const cl::Context& Device::context() const { return state_->context; }
const cl::Device& Device::device() const { return state_->device; }
cl::CommandQueue& Device::queue() const { return state_->queue; }
bool Device::profiling() const { return state_->profiling; }

cl::Program Device::program(const std::string& kernel_file, const std::vector<std::string>& defines) const {
  std::string source = kernel_source(kernel_file);
  std::string options = "-cl-std=CL1.2";
  if (state_->info.fp64) options += " -DRTCL_HAS_FP64";
  for (const auto& d : defines) options += (d.rfind("-cl-", 0) == 0 ? " " : " -D") + d;
  auto key = std::make_tuple(std::hash<std::string>{}(source), options);
  std::lock_guard lock(state_->cache_mutex);
  if (auto it = state_->programs.find(key); it != state_->programs.end()) return it->second;
  return with_cl_errors([&] {
    cl::Program program(state_->context, source);
    try {
      program.build(std::vector<cl::Device>{state_->device}, options.c_str());
    } catch (const cl::Error&) {
      std::string log = program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(state_->device);
      throw Error("building kernel file " + kernel_file + " (options: " + options + ") failed on " +
                  state_->info.name + ":\n" + name_source_lines(log, source));
    }
    state_->programs.emplace(key, program);
    return program;
  });
}

namespace {

struct Release {
  std::shared_ptr<std::atomic<std::size_t>> live_bytes;
  std::size_t bytes;
};

void CL_CALLBACK released(cl_mem, void* user_data) {
  auto* release = static_cast<Release*>(user_data);
  release->live_bytes->fetch_sub(release->bytes);
  delete release;
}

}  // namespace

// A driver may run a released buffer's destructor callback after
// clReleaseMemObject has returned (NVIDIA's does; PoCL's runs it inside):
// before refusing a buffer that would fit but for what rtcl still counts as
// live, the queue is finished and the pending callbacks get up to a second.
void Device::check_fits(std::size_t bytes, const std::string& what) const {
  const DeviceLimits limits{state_->info.max_alloc_bytes, state_->info.global_mem_bytes};
  auto fits = [&] { return fits_global_memory(limits, bytes, *state_->live_bytes); };
  if (bytes <= limits.global_mem_bytes && !fits()) {
    state_->queue.finish();
    for (auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
         !fits() && std::chrono::steady_clock::now() < deadline;)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  check_allocation(limits, bytes, *state_->live_bytes, what, state_->info.name);
}

cl::Buffer Device::allocate(std::size_t bytes, const char* what, cl_mem_flags flags) const {
  check_fits(bytes, what);
  std::size_t charged = std::max<std::size_t>(bytes, 1);
  return with_cl_errors([&] {
    cl::Buffer buffer(state_->context, flags, charged);
    auto* release = new Release{state_->live_bytes, charged};
    state_->live_bytes->fetch_add(charged);
    if (::clSetMemObjectDestructorCallback(buffer(), released, release) != CL_SUCCESS) {
      state_->live_bytes->fetch_sub(charged);  // not tracked: counted as free
      delete release;
    }
    return buffer;
  });
}

std::size_t Device::allocated_bytes() const { return *state_->live_bytes; }

cl::Buffer Device::upload(const void* data, std::size_t bytes, const char* what) const {
  cl::Buffer buffer = allocate(bytes, what, CL_MEM_READ_ONLY);
  if (bytes > 0)
    with_cl_errors([&] { state_->queue.enqueueWriteBuffer(buffer, CL_TRUE, 0, bytes, data); });
  return buffer;
}

}  // namespace rtcl
