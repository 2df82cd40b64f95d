// Host ray tests of the bounding volumes: the same source as the device's
// (kernels/shared/volumes.h), compiled as C++. Contract there: conservative,
// safe for ±0 direction components, invalid rays miss.
#pragma once

#include "rtcl/bounds/bounds_layouts.hpp"
#include "rtcl/shared/volumes.h"
