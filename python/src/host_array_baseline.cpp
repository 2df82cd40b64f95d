// rtcl._HostArrayBaseline: the library's C++ host-array call (Accel::trace
// on Ray records into Hit records, as rtcl_query_bench and a C++ caller
// make it) on a RaycastingScene's rays, for bench/python_bench.py to time
// in the same process as cast_rays, call by call. Internal (not part of
// the module's API, docs/python.md): the rays are packed once, here, and
// each trace() is the library call alone.
#include <pybind11/pybind11.h>

#include <limits>
#include <memory>
#include <vector>

#include "array_io.hpp"
#include "mesh_scene.hpp"

namespace rtcl::python {

namespace {

class HostArrayBaseline {
 public:
  HostArrayBaseline(const MeshScene& scene, py::handle rays_in) {
    const char* call = "_HostArrayBaseline";
    const FloatRecords rays = float_records(rays_in, 6, call, "rays");
    if (scene.instanced()) throw py::value_error("_HostArrayBaseline: scene has instances; the baseline is of a flat scene");
    built_ = scene.snapshot().built;
    if (!built_->flat || !built_->flat->accel)
      throw py::value_error("_HostArrayBaseline: scene has nothing to hit");
    rays_.resize(rays.count);
    pack_rays(rays, 0, 0.0f, std::numeric_limits<float>::infinity(), rays_);
    hits_.resize(rays.count);
  }

  // One closest-hit call over every ray (GIL released).
  void trace() {
    py::gil_scoped_release release;
    built_->flat->accel->trace(Query::closest, Rays(std::span<const Ray>(rays_)), std::span<Hit>(hits_));
  }

 private:
  std::shared_ptr<const BuiltScene> built_;
  std::vector<Ray> rays_;
  std::vector<Hit> hits_;
};

}  // namespace

void bind_host_array_baseline(py::module_& m) {
  py::class_<HostArrayBaseline>(m, "_HostArrayBaseline", R"doc(
Internal, for bench/python_bench.py: the library's C++ host-array call on
the rays of a flat RaycastingScene (packed once, here); trace() is that
call alone, closest hit, incoherent. Not part of the API.)doc")
      .def(py::init<const MeshScene&, py::handle>(), py::arg("scene"), py::arg("rays"))
      .def("trace", &HostArrayBaseline::trace);
}

}  // namespace rtcl::python
