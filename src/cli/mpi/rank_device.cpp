#include "mpi/rank_device.hpp"

#include <cstdlib>
#include <vector>

#include "flag_names.hpp"
#include "rtcl/error.hpp"

namespace rtcl::cli {

Device open_rank_device(const std::string& selector, int local_rank) {
  if (const char* env = std::getenv("RTCL_DEVICE"); !selector.empty() || (env && *env))
    return open_device_flag(selector);  // --device, else $RTCL_DEVICE
  std::vector<DeviceInfo> infos = list_devices();
  if (infos.empty()) throw Error("no OpenCL device found (`rtcl devices` lists them)");
  return Device::open(std::to_string(infos[static_cast<std::size_t>(local_rank) % infos.size()].index));
}

}  // namespace rtcl::cli
