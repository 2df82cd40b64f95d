// Host view of the records shared with the kernels (kernels/shared/layouts.h):
// Ray (32 bytes) and Hit (16 bytes) are the public, stable formats of ray and
// hit buffers; both are arrays of 4-byte little-endian fields, no padding.
#pragma once

#include "rtcl/shared/layouts.h"
