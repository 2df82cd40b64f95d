// The Python class rtcl.RaycastingScene (raycasting_scene.cpp) and its static
// create_rays_pinhole (pinhole.cpp).
#pragma once

#include <pybind11/pybind11.h>

#include "mesh_scene.hpp"

namespace rtcl::python {

void bind_raycasting_scene(pybind11::module_& m);
void bind_pinhole(pybind11::class_<MeshScene>& cls);

}  // namespace rtcl::python
