// The OpenCL device of an MPI rank: --device when given, else $RTCL_DEVICE
// when set (as in every subcommand), else device (local rank mod device
// count) of list_devices(), so that the ranks of one host spread over its
// devices (two GPUs: two ranks, one each).
#pragma once

#include <string>

#include "rtcl/device.hpp"

namespace rtcl::cli {

Device open_rank_device(const std::string& selector, int local_rank);

}  // namespace rtcl::cli
