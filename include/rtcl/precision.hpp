// Precision levels: the speed/accuracy trade of every trace kernel, chosen
// per structure at build time. Each level is its own specialised program
// (-D options, see precision_build_options), never a runtime branch.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "rtcl/device.hpp"

namespace rtcl {

enum class Precision {
  // Moller-Trumbore triangles (not watertight), slab test without
  // conservative widening, -cl-fast-relaxed-math; the renderer spawns
  // secondary rays with a fixed offset. May leak through shared edges.
  fast,
  // Watertight triangles (Woop, Benthin, Wald 2013), conservative slab
  // bounds (Ize 2013), spawn offsets that scale with the hit point. The
  // default: no leaks, at most a few percent slower than fast.
  robust,
  // robust plus a double-precision re-test of every candidate float cannot
  // decide (near an edge, near tmin / tmax, near-ties between candidates):
  // the primitive and t (double, rounded to float) of a double-precision
  // evaluation; the smaller primitive id wins an exact tie of t. Needs a
  // device with cl_khr_fp64.
  exact,
};

// "fast", "robust", "exact", in that order.
const std::vector<std::string>& precision_names();
std::string_view precision_name(Precision precision);

// Throws Error "precision "NAME": unknown precision level (known: ...)".
Precision parse_precision(std::string_view name);

// "" when the device can run the level, else why not (exact without fp64).
std::string precision_unsupported(const DeviceInfo& device, Precision precision);

// Throws Error "precision "NAME": WHY" when precision_unsupported is not "",
// e.g. precision "exact": exact needs double precision on the device
// (cl_khr_fp64), which DEVICE lacks.
void require_precision(const DeviceInfo& device, Precision precision);

// The program options of a trace kernel at this level: -D defines
// (RTCL_PRECISION_FAST / _ROBUST / _EXACT) and, for fast,
// -cl-fast-relaxed-math (Device::program passes "-cl-..." entries as they are).
std::vector<std::string> precision_build_options(Precision precision);

}  // namespace rtcl
