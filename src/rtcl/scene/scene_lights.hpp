// What `rtcl render` and rtcl.render do with a scene that declares no light
// (docs/cli.md, "Scenes without lights"; docs/python.md, "Rendering"): its emissive triangles light it as area lights,
// one light {"type": "emissive"} whose intensity scales the brightest
// channel of their area-weighted mean emission to 1 (as bright as a white
// point light of intensity 1); without emissive triangles, or where the
// method takes point lights only (--method beam), a warning says that the
// image shows only emission and the ambient term.
#pragma once

#include <string>

#include "rtcl/scene/scene_description.hpp"

namespace rtcl {

struct LightNotice {
  std::string note;     // the light added, and why
  std::string warning;  // the scene stays without light
};

// For a scene with no light: adds the emissive light when it has emissive
// triangles and `area_lights` (the method renders area lights), and says
// what it did. A scene with a light is left as it is (no notice).
// `point_lights_only` names the method that renders point lights only, as
// the caller's user gives it (the CLI's "--method beam"), for the warning.
LightNotice default_lights(SceneDescription& scene, bool area_lights,
                           const std::string& point_lights_only = "--method beam");

}  // namespace rtcl
