// The built-in scene `rtcl render` draws when no scene file is given: a
// Cornell-style box (2 x 2 x 2 units, open at the front, red left and green
// right wall) with a mirror sphere, a glass sphere (refraction, Fresnel
// reflection), a glass block (total internal reflection on its inner faces),
// an emissive ceiling panel and one point light that casts hard shadows.
// Needs no file.
#pragma once

#include "rtcl/scene/scene_description.hpp"

namespace rtcl {

SceneDescription default_scene();

}  // namespace rtcl
