// Devices for the module: rtcl.devices() and the device= argument.
#pragma once

#include <pybind11/pybind11.h>

#include "rtcl/device.hpp"

namespace rtcl::python {

// The device a `device=` argument names: None ($RTCL_DEVICE, else device 0),
// an index of rtcl.devices() or a name substring. Opened once per selector
// and kept for the process, so that scenes and renders share one context,
// queue and kernel cache. py::type_error for another type, py::value_error
// with the library's message ("device "9": no such device ...") when
// nothing matches.
Device open_device(const pybind11::handle& device);

void bind_devices(pybind11::module_& m);

}  // namespace rtcl::python
