// One-dimensional kernel launches with a fixed work-group size. The global
// size is rounded up to a multiple of it (every kernel checks its index
// against its count). A fixed local size matters on PoCL: it generates code
// per local size, and with the default (NULL) it picks one from each global
// size, so every new queue length would cost a code generation (a
// fraction of a second or more each).
#pragma once

#include <cstddef>
#include <vector>

#include "rtcl/device.hpp"

namespace rtcl {

inline constexpr std::size_t launch_group_size = 64;

// Enqueues `kernel` over `count` work-items (count > 0) after `wait`.
cl::Event launch(const Device& device, const cl::Kernel& kernel, std::size_t count,
                 const std::vector<cl::Event>& wait);

}  // namespace rtcl
