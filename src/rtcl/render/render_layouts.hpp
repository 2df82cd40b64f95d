// Host view of the renderer's device records (kernels/shared/render_layouts.h).
#pragma once

#include "rtcl/layouts.hpp"
#include "rtcl/shared/render_layouts.h"
