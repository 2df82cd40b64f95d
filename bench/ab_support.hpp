// Helpers of the A/B programs in bench/ (kernel_ab, ray_sort, build_ab):
// event times, order statistics of repeated runs, comma lists, the ROUNDS
// argument, the image side, the scenes directory and a bench/ scene with
// its geometry.
#pragma once

#include "rtcl/bench/scene_catalog.hpp"
#include "rtcl/opencl.hpp"
#include "rtcl/error.hpp"
#include "rtcl/geometry.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "rtcl/scene/procedural.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <sstream>
#include <string>
#include <vector>

namespace rtcl::bench {

// Waits for e, then returns its kernel time in ms (profiling start to end).
inline double kernel_ms(const cl::Event& e) {
  e.wait();
  return static_cast<double>(e.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                             e.getProfilingInfo<CL_PROFILING_COMMAND_START>()) *
         1e-6;
}

// The median of a non-empty set of times (the mean of the middle two for an
// even count).
inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

inline double fastest(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

// The non-empty items of a comma-separated list.
inline std::vector<std::string> split(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream in(list);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

// The ROUNDS argument: a positive count, else an Error naming it.
inline int parse_rounds(const char* text) {
  const int rounds = std::atoi(text);
  if (rounds < 1) throw Error(std::string("ROUNDS must be a positive number, not '") + text + "'");
  return rounds;
}

// $RTCL_SCENES_DIR, else `fallback` (the build's ../shared/scenes).
inline std::string scenes_dir_or(const char* fallback) {
  const char* dir = std::getenv("RTCL_SCENES_DIR");
  return dir && *dir ? dir : fallback;
}

// $RTCL_BENCH_RES, the image side of the bench/ ray sets: `fallback` when
// unset, else a positive number or an Error naming it.
inline int bench_res(int fallback) {
  const char* res_env = std::getenv("RTCL_BENCH_RES");
  const int res = res_env && *res_env ? std::atoi(res_env) : fallback;
  if (res < 1) throw Error("RTCL_BENCH_RES must be a positive number");
  return res;
}

// The bench/ scene called `name`, which has a fixed camera and light, else
// an Error naming it.
inline const SceneSpec& fixed_camera_scene(const std::string& name) {
  const SceneSpec* spec = find_scene_spec(name);
  if (!spec || spec->fit)
    throw Error("scene '" + name +
                "': not a bench/ scene with a fixed camera (bunny, dragon, sponza, sibenik, teapot-stadium)");
  return *spec;
}

// A bench/ scene's geometry: its mesh, inside its stadium where it has one.
inline Geometry spec_geometry(const SceneSpec& spec, const std::string& scenes_dir) {
  Geometry geometry = load_mesh(scenes_dir + "/" + spec.file).geometry;
  if (spec.stadium > 0.0f) add_stadium(geometry, spec.stadium);
  return geometry;
}

// main() of an A/B program: run(argc, argv)'s status, or one line naming
// the program and the error and status 1.
inline int run_main(const char* program, int (*run)(int, char**), int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", program, e.what());
    return 1;
  }
}

}  // namespace rtcl::bench
