// The built-in forest (`rtcl render --builtin forest`): copies of the
// Stanford bunny on a ground plane, every one an object of the one shared
// bunny shape (MeshShape), so the renderer builds the bunny once and places
// it by instances (docs/scenes-and-instances.md). Each bunny stands on a
// square grid with a random offset, turn about the vertical and size, from
// a fixed seed: the same scene at every run. A few bunnies in the front row
// move (a hop forwards over keyframes 0 .. 1), for motion blur and
// `--frames`.
#pragma once

#include <cstddef>
#include <string>

#include "rtcl/scene/scene_description.hpp"

namespace rtcl {

struct ForestOptions {
  std::size_t bunnies = 10000;  // >= 1
  std::size_t moving = 8;       // of them, in the front row (at most the row's length)
};

// The forest with the bunny read from `bunny_path` (an OBJ file: the
// scenes directory's stanford_bunny/bunny.obj). Throws Error naming the
// path when it cannot be read, and naming the option for bunnies = 0.
SceneDescription forest_scene(const std::string& bunny_path, const ForestOptions& options = {});

}  // namespace rtcl
