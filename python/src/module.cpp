// The Python module `rtcl` (docs/python.md): RaycastingScene with Open3D's
// names, render, devices. Errors: arguments the module or the library
// refuse raise ValueError (a wrong value) or TypeError (a wrong type or
// dtype), before any work; failures of the device or the driver (OpenCL
// errors, memory, kernel builds) raise RuntimeError; each carries the
// library's one-line message.
#include <pybind11/pybind11.h>

#include "devices.hpp"
#include "raycasting_scene.hpp"
#include "rtcl/error.hpp"

namespace rtcl::python {
void bind_render(pybind11::module_& m);
void bind_host_array_baseline(pybind11::module_& m);
}

PYBIND11_MODULE(rtcl, m) {
  namespace py = pybind11;
  m.doc() = "rtcl: ray queries and rendering on OpenCL devices (docs/python.md)";
  m.attr("__version__") = RTCL_VERSION_STRING;
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const rtcl::Error& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    } catch (const cl::Error& e) {
      PyErr_SetString(PyExc_RuntimeError,
                      (std::string(e.what()) + " failed: OpenCL error " + std::to_string(e.err())).c_str());
    }
  });
  rtcl::python::bind_devices(m);
  rtcl::python::bind_raycasting_scene(m);
  rtcl::python::bind_render(m);
  rtcl::python::bind_host_array_baseline(m);
}
