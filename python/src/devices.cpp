#include "devices.hpp"

#include <map>
#include <mutex>
#include <string>

#include "rtcl/error.hpp"

namespace rtcl::python {

namespace py = pybind11;

Device open_device(const py::handle& device) {
  std::string selector;
  if (device.is_none()) {
    selector = "";
  } else if (py::isinstance<py::int_>(device) && !py::isinstance<py::bool_>(device)) {
    const long long index = device.cast<long long>();
    if (index < 0) throw py::value_error("device " + std::to_string(index) + ": must be >= 0 (see rtcl.devices())");
    selector = std::to_string(index);
  } else if (py::isinstance<py::str>(device)) {
    selector = device.cast<std::string>();
  } else {
    throw py::type_error("device must be None, an index or a name, got " +
                         py::str(py::type::of(device).attr("__name__")).cast<std::string>());
  }
  // Never destroyed: the OpenCL driver may be gone when static objects are.
  static std::mutex mutex;
  static auto* by_selector = new std::map<std::string, Device>();
  static auto* by_index = new std::map<std::size_t, Device>();
  std::lock_guard lock(mutex);
  if (auto it = by_selector->find(selector); it != by_selector->end()) return it->second;
  try {
    Device opened = Device::open(selector);
    Device& shared = by_index->try_emplace(opened.info().index, opened).first->second;
    by_selector->emplace(selector, shared);
    return shared;
  } catch (const Error& e) {
    // The library names its own parameter: Device::open selector "X": ...
    std::string message = e.what();
    const std::string prefix = "Device::open selector";
    if (message.rfind(prefix, 0) == 0) message = "device" + message.substr(prefix.size());
    throw py::value_error(message);
  }
}

void bind_devices(py::module_& m) {
  m.def(
      "devices",
      [] {
        py::list out;
        for (const DeviceInfo& d : list_devices()) {
          py::dict info;
          info["index"] = d.index;
          info["platform"] = d.platform;
          info["name"] = d.name;
          info["type"] = d.type;
          info["version"] = d.version;
          info["compute_units"] = d.compute_units;
          info["global_mem_bytes"] = d.global_mem_bytes;
          info["max_alloc_bytes"] = d.max_alloc_bytes;
          info["fp64"] = d.fp64;
          out.append(info);
        }
        return out;
      },
      R"doc(The OpenCL devices, as `rtcl devices` lists them: a list of dicts with index,
platform, name, type ("cpu", "gpu", ...), version, compute_units,
global_mem_bytes, max_alloc_bytes and fp64. device=index selects one.)doc");
}

}  // namespace rtcl::python
