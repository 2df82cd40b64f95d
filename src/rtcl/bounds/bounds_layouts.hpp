// Host view of the bounding-volume records shared with the kernels
// (kernels/shared/bounds_layouts.h).
#pragma once

#include "rtcl/layouts.hpp"
#include "rtcl/shared/bounds_layouts.h"
