// What one `rtcl render` writes: one image; the frames of an animation
// (--frames A:B, the output a pattern such as out_%04d.png); or one image
// per sample count of a sweep (--spp-sweep 1,4,16, the pattern filled with
// the count). An animation's frames differ in time: frame f's shutter is the
// camera's [open, close] moved by f * --frame-time along the keyframe time
// axis (default frame time: close - open, so consecutive shutters abut), and
// moving objects continue linearly beyond their keyframes. Shared by the
// single-process render and the distributed one under mpirun, which hands
// out (unit, tile) jobs.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "render_options.hpp"
#include "rtcl/scene/scene_description.hpp"

namespace rtcl::cli {

enum class UnitKind { single, frames, sweep };

struct RenderUnit {
  std::string output;      // the file this unit writes
  std::int64_t frame = 0;  // animation frame (frames only)
  std::uint32_t spp = 1;   // samples per pixel of this unit
};

struct RenderUnits {
  UnitKind kind = UnitKind::single;
  double frame_time = 0.0;  // keyframe time between consecutive frames (frames only)
  std::vector<RenderUnit> units;
};

// The units of the options for `scene` with `spp` the plan's samples per
// pixel. Throws UsageError naming the option for: a malformed or reversed
// --frames range (A:B, 0 <= A <= B, at most 100000 frames), a bad
// --spp-sweep list (integers 1 .. 65536, no repeats), both at once,
// --frame-time without --frames or not positive, an animation of a scene
// with nothing moving or with an empty shutter and no --frame-time, and an
// output name without exactly one %d / %0Nd field (N 1..9) while it names
// several files (or with one while it names one); and a frame whose shutter
// interval makes some motion singular (naming the frame and the object's
// motion key). Checks each output path (check_image_output_flag).
RenderUnits plan_units(const RenderOptions& o, const SceneDescription& scene, std::uint32_t spp);

// The scene of a unit: for a frame, the camera's shutter moved to the
// frame's interval (checked by plan_units); otherwise the scene itself.
SceneDescription unit_scene(const SceneDescription& scene, const RenderUnits& units, const RenderUnit& unit);

// `pattern` with its one %d / %0Nd field replaced by `value`.
std::string expand_output_pattern(const std::string& pattern, std::int64_t value);

}  // namespace rtcl::cli
