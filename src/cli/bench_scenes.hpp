// The scenes of `rtcl bench`: the shared meshes of bench/support/scene_catalog
// ("bunny", ...) and procedural ones built at a chosen size
// (rtcl/scene/procedural.hpp): "sphereflake:levels=3", "tetra:levels=6",
// "mount:levels=6", "soup:count=100000", "teapot-stadium" is a mesh spec.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "bench/support/scene_catalog.hpp"
#include "rtcl/layouts.hpp"
#include "rtcl/geometry.hpp"

namespace rtcl::cli {

// A parsed --scene entry: checked (name, parameters, file present) before
// any device work.
struct BenchSceneSpec {
  std::string text;  // as given, canonical: "tetra:levels=6"
  std::string kind;  // a scene_specs() name, or sphereflake / tetra / mount / soup
  std::int64_t size = 0;  // levels or count of a procedural scene
  std::string file;  // the mesh path of a shared scene
};

// Splits "bunny,soup:count=1000,tetra" into entries; a piece without ':'
// that holds '=' continues the previous entry's parameters.
std::vector<std::string> split_spec_list(const std::string& text);

// Throws UsageError "--scene TEXT: PROBLEM" for an unknown scene, parameter
// or out-of-range size, and for a shared mesh scene when `scenes_dir` is ""
// (neither --scenes-dir nor $RTCL_SCENES_DIR given); Error naming the
// missing file of a shared scene.
BenchSceneSpec parse_bench_scene(const std::string& text, const std::string& scenes_dir);

// Names --scene accepts, for messages and --help.
std::string bench_scene_names();

struct LoadedBenchScene {
  BenchSceneSpec spec;
  Geometry geometry;  // validated
  bench::Camera camera;
  glm::vec3 light{0.0f};
  double load_ms = 0.0;  // file read or generation, and validation
};

LoadedBenchScene load_bench_scene(const BenchSceneSpec& spec);

}  // namespace rtcl::cli
