// The built-in scene that shows every distributed effect with no files
// (`rtcl render --builtin showcase`): the default scene's room and glass
// sphere, lit by a quad area light under its ceiling panel (soft shadows),
// a glossy metal sphere (roughness 0.2) in place of the mirror, the glass
// block, a small sphere close to the camera, out of focus (thin lens of
// radius 0.04 focused on the glass sphere), and a ball that moves across
// the room during the shutter (motion blur).
#pragma once

#include "rtcl/scene/scene_description.hpp"

namespace rtcl {

SceneDescription showcase_scene();

// The built-in scenes by name: "default", "showcase", "forest" (its bunny
// from `scenes_dir`/stanford_bunny/bunny.obj, rtcl/scene/forest_scene.hpp).
// Throws Error (builtin_scene name "NAME": ...) naming the known names for
// another, or for the forest without a scenes directory.
SceneDescription builtin_scene(const std::string& name, const std::string& scenes_dir = "");

}  // namespace rtcl
