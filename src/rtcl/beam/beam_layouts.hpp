// Host view of the beam tracer's device records (kernels/shared/beam_layouts.h).
#pragma once

#include "rtcl/layouts.hpp"
#include "rtcl/shared/beam_layouts.h"
