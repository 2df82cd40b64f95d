// Host view of the renderer's device records (kernels/shared/render_layouts.h)
// and of the sample patterns both sides draw (kernels/shared/sampling.h).
#pragma once

#include "rtcl/layouts.hpp"
#include "rtcl/shared/render_layouts.h"
#include "rtcl/shared/sampling.h"
