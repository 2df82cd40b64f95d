// rtcl's public API in one include (docs/api.md): devices, geometry from
// arrays, acceleration structures and their queries on host arrays or
// OpenCL buffers, scenes of meshes and instances, errors.
#pragma once

#include "rtcl/aabb.hpp"
#include "rtcl/accel.hpp"
#include "rtcl/accel_options.hpp"
#include "rtcl/device.hpp"
#include "rtcl/error.hpp"
#include "rtcl/geometry.hpp"
#include "rtcl/opencl.hpp"
#include "rtcl/precision.hpp"
#include "rtcl/queries.hpp"
#include "rtcl/scene.hpp"
