#pragma once

#include <memory>

#include "rtcl/accel.hpp"

namespace rtcl {

// Every ray against every primitive: O(rays x primitives), the reference.
// Its registry entry: no options.
const StructureSpec& brute_structure();

std::unique_ptr<Accel> make_brute(const Device& device, const Geometry& geometry, const AccelConfig& config = {});

}  // namespace rtcl
