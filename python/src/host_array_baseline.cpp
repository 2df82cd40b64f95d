// rtcl._HostArrayBaseline: the library's C++ host-array call (Accel::trace
// on Ray records into Hit records, as rtcl_query_bench and a C++ caller
// make it) on a RaycastingScene's rays, for bench/python_bench.py to time
// in the same process as cast_rays (trace: closest hit) and
// test_occlusions (occluded: any hit), call by call. Internal (not part of
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
  HostArrayBaseline(const MeshScene& scene, py::handle rays_in, double tnear, double tfar) {
    const char* call = "_HostArrayBaseline";
    const FloatRecords rays = float_records(rays_in, 6, call, "rays");
    if (scene.instanced()) throw py::value_error("_HostArrayBaseline: scene has instances; the baseline is of a flat scene");
    built_ = scene.snapshot().built;
    if (!built_->flat || !built_->flat->accel)
      throw py::value_error("_HostArrayBaseline: scene has nothing to hit");
    rays_.resize(rays.count);
    if (!(tnear >= 0.0 && tfar >= tnear))
      throw py::value_error("_HostArrayBaseline: tnear and tfar must satisfy 0 <= tnear <= tfar");
    pack_rays(rays, 0, static_cast<float>(tnear), static_cast<float>(tfar), rays_);
    hits_.resize(rays.count);
  }

  // One closest-hit call over every ray (GIL released): cast_rays' call.
  void trace() { run(Query::closest); }

  // One any-hit call over every ray (GIL released): test_occlusions' call.
  void occluded() { run(Query::any); }

 private:
  std::shared_ptr<const BuiltScene> built_;
  std::vector<Ray> rays_;
  std::vector<Hit> hits_;

  void run(Query query) {
    py::gil_scoped_release release;
    built_->flat->accel->trace(query, Rays(std::span<const Ray>(rays_)), std::span<Hit>(hits_));
  }
};

}  // namespace

void bind_host_array_baseline(py::module_& m) {
  py::class_<HostArrayBaseline>(m, "_HostArrayBaseline", R"doc(
Internal, for bench/python_bench.py: the library's C++ host-array call on
the rays of a flat RaycastingScene (packed once, here, with tnear and
tfar); trace() is that call alone, closest hit, and occluded() any hit,
both incoherent. Not part of the API.)doc")
      .def(py::init<const MeshScene&, py::handle, double, double>(), py::arg("scene"), py::arg("rays"),
           py::arg("tnear") = 0.0, py::arg("tfar") = std::numeric_limits<double>::infinity())
      .def("trace", &HostArrayBaseline::trace)
      .def("occluded", &HostArrayBaseline::occluded);
}

}  // namespace rtcl::python
