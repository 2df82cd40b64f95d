// The options of `rtcl render` and what they resolve to for a scene: shared
// by the single-process render (render_command.cpp) and the distributed one
// under mpirun (mpi/mpi_render.cpp).
#pragma once

#include <cstdint>
#include <string>

#include "rtcl/accel.hpp"
#include "rtcl/render/renderer.hpp"
#include "rtcl/scene/scene_description.hpp"

namespace rtcl::cli {

struct RenderOptions {
  std::string scene;
  std::string builtin;  // a built-in scene's name (rtcl/scene/showcase_scene.hpp) when no scene file is given
  std::string output = "render.png";
  std::string accel;
  std::string precision;  // "": the scene file's, else robust
  std::string device;
  std::uint32_t width = 512, height = 0;  // height 0: from the camera's aspect
  std::uint32_t depth = 5, spp = 1;
  float min_weight = 1e-3f;
  std::uint32_t batch = 1u << 17;
  std::string sampler = "stratified", filter = "box";
  std::uint32_t seed = 0, light_samples = 1;
  // ray: Whitted ray tracing, every pixel traced (src/rtcl/render);
  // selective: block corners traced, blocks subdivided where they differ,
  // the rest interpolated; wavelet: a coarse pass, then whole blocks where
  // its Haar coefficients are large, under a budget (rtcl/render/
  // selective.hpp, wavelet.hpp); beam: beam tracing with reflection beams
  // (src/rtcl/beam/beam_renderer.hpp), with the depth order of its walk
  // (exact | key).
  std::string method = "ray";
  std::string beam_order = "exact";
  std::uint32_t selective_block = 8;
  float selective_threshold = 0.05f, selective_depth = 0.1f, wavelet_budget = 0.25f;
  // Several images (render_units.hpp): an animation's frames "A:B" with
  // `frame_time` keyframe time between frames (0: the shutter's length), or
  // samples-per-pixel values "1,4,16"; `output` then holds a %d field.
  std::string frames, spp_sweep;
  double frame_time = 0.0;
  bool quiet = false;
  bool verbose = false;
  // Under mpirun only: tile side in pixels (a multiple of 8), the order
  // tiles are handed out in (rows | shuffled), and where ranks get the
  // scene from (root: read on rank 0 and broadcast; each: every rank reads
  // the file itself, e.g. from a shared file system).
  std::uint32_t tile = 64;
  std::string tile_order = "rows";
  std::string scene_from = "root";
};

// What the options mean for one scene: image settings, structure and its
// configuration. Throws Error for a bad precision name.
struct RenderPlan {
  RenderSettings settings;
  AccelConfig config;
  std::string accel;
};
RenderPlan plan_render(const RenderOptions& o, const SceneDescription& scene);

// The scene the options name: the scene file, else the --builtin scene
// (default: "default"), its notes printed on stderr. Throws Error for a
// file and --builtin both, or an unknown built-in name.
SceneDescription load_render_scene(const RenderOptions& o);
// The same without printing the notes (every rank but the first).
SceneDescription read_render_scene(const RenderOptions& o);

// The summary line(s) on stdout: rays, time and rate; with --verbose the
// stage times. `devices`: the device name, or how many ranks and devices.
void print_render_summary(const RenderOptions& o, const RenderPlan& plan, const std::string& devices,
                          const RenderStats& stats, const std::vector<std::string>& defines);

}  // namespace rtcl::cli
