// The OpenCL device layer: discovery, selection, adoption of a caller's
// context and queue, and the per-device program cache.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "rtcl/opencl.hpp"

namespace rtcl {

struct DeviceInfo {
  std::size_t index = 0;  // position in list_devices(): what --device N selects
  std::string platform;
  std::string name;
  std::string type;     // "cpu", "gpu", "accelerator", "other"
  std::string version;  // CL_DEVICE_VERSION
  unsigned compute_units = 0;
  // CL_DEVICE_GLOBAL_MEM_SIZE and CL_DEVICE_MAX_MEM_ALLOC_SIZE (largest
  // buffer), each lowered by its environment variable (cl/device_limits.hpp)
  std::size_t global_mem_bytes = 0;
  std::size_t max_alloc_bytes = 0;
  bool fp64 = false;
};

// Every device of every platform, in platform then device order. Empty when
// no OpenCL platform is installed.
std::vector<DeviceInfo> list_devices();

class Device {
 public:
  // selector: "" uses $RTCL_DEVICE when set, else device 0; a number selects
  // by list_devices() index; anything else is a case-insensitive substring of
  // "platform name device name". Throws Error naming the selector
  // (Device::open selector "99": no such device ...; RTCL_DEVICE "99": ...
  // when it came from the environment) when nothing matches or no device
  // exists.
  static Device open(std::string_view selector = {});

  // Uses a context, device and queue the caller already has (retained, not
  // owned). The queue may be in-order or out-of-order; rtcl orders its own
  // commands with events.
  static Device adopt(cl_context context, cl_device_id device, cl_command_queue queue);

  const DeviceInfo& info() const;
  const cl::Context& context() const;
  const cl::Device& device() const;
  cl::CommandQueue& queue() const;
  bool profiling() const;  // the queue records event times

  // The program built from an embedded kernel file (path under kernels/,
  // e.g. "accel/bvh.cl") with -D defines ("NAME" or "NAME=VALUE"; an entry
  // starting with "-cl-", e.g. "-cl-fast-relaxed-math", is passed as it is). Cached per
  // device + source hash + options; a build failure throws Error with the log.
  cl::Program program(const std::string& kernel_file, const std::vector<std::string>& defines) const;

  // Throws Error naming `what`, the device and both numbers when `bytes`
  // exceed the largest buffer the device allows, or when they do not fit in
  // its global memory beside the buffers already allocated through this
  // Device (limits: DeviceInfo, lowered by RTCL_MAX_ALLOC_BYTES and
  // RTCL_MAX_GLOBAL_BYTES, see cl/device_limits.hpp). For callers that
  // refuse a whole job before its first upload.
  void check_fits(std::size_t bytes, const std::string& what) const;

  // A device buffer holding a copy of host data; allocate and upload check
  // it first (check_fits), so a refused buffer is never created.
  cl::Buffer upload(const void* data, std::size_t bytes, const char* what) const;
  cl::Buffer allocate(std::size_t bytes, const char* what, cl_mem_flags flags = CL_MEM_READ_WRITE) const;

  // Bytes of the device buffers allocated through this Device (and its
  // copies) that are still alive: structures, scenes, renderers, ray sorts
  // and the batch buffers of host-array calls in flight; what check_fits
  // counts as already held. Not counted: buffers the caller creates itself,
  // and the buffers on the caller's own arrays through which host-array calls
  // run on CPU devices (host memory). A released buffer leaves the count when
  // the driver runs its destructor callback (PoCL: during the release; some
  // drivers a little later).
  std::size_t allocated_bytes() const;

  struct State;

 private:
  explicit Device(std::shared_ptr<State> state);
  std::shared_ptr<State> state_;
};

}  // namespace rtcl
