// What the library's structures share when they choose and build their
// trace kernels (internal).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "rtcl/accel.hpp"

namespace rtcl {

// Occluder runs (Accel::TraceKernels::occluder_run) of a structure whose
// any-hit kernels have them (the BVHs, the kd-tree, the BSP, the grid and
// the octrees): the structure's `occluder_run` option when > 0, else
// kCpuOccluderRun on CPU devices and 1 on others (a GPU needs every ray or
// packet as a work-item of its own to fill its lanes).
inline constexpr std::uint32_t kCpuOccluderRun = 16;
std::size_t occluder_run_for(std::uint32_t requested, const DeviceInfo& device);
// That option: one declaration that such structures list.
const OptionSpec& occluder_run_option();

// Whether a structure's packet kernel serves its Coherence::coherent calls
// (`bvh`, `bvh-ploc` and `kdtree`; `bvh-packet` and `kdtree-packet` take it
// for every call): on CPU devices, where a packet's eight rays fill a
// work-item's float8 lanes; not on others, where every ray is a work-item
// of its own (docs/benchmarks.md).
bool packets_for_coherent_calls(const DeviceInfo& device);

// The -D options every trace program needs for this geometry.
std::vector<std::string> primitive_defines(const Geometry& geometry);

}  // namespace rtcl
