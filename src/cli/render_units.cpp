#include "render_units.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <optional>
#include <set>

#include "cli_errors.hpp"
#include "flag_names.hpp"
#include "rtcl/error.hpp"
#include "rtcl/render/image.hpp"
#include "rtcl/scene/motion.hpp"

namespace rtcl::cli {

namespace {

// The one integer field of a pattern: its position, length and width.
struct Field {
  std::size_t at = 0, length = 0;
  int width = 0;  // 0: %d; N: %0Nd
};

// Every '%' in `pattern` and whether they form exactly one valid field.
std::optional<Field> integer_field(const std::string& pattern, int* percents) {
  std::optional<Field> field;
  *percents = 0;
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') continue;
    ++*percents;
    std::size_t j = i + 1;
    int width = 0;
    if (j < pattern.size() && pattern[j] == '0') {
      ++j;
      if (j >= pattern.size() || pattern[j] < '1' || pattern[j] > '9') return std::nullopt;
      width = pattern[j] - '0';
      ++j;
    }
    if (j >= pattern.size() || pattern[j] != 'd') return std::nullopt;
    field = Field{i, j + 1 - i, width};
  }
  return *percents == 1 ? field : std::nullopt;
}

std::int64_t parse_integer(const std::string& text, const std::string& option, const std::string& whole) {
  std::size_t used = 0;
  long long v = 0;
  try {
    v = std::stoll(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (text.empty() || used != text.size() || !(text[0] == '-' || std::isdigit(static_cast<unsigned char>(text[0]))))
    throw UsageError(option + " " + whole + ": '" + text + "' is not an integer");
  return v;
}

}  // namespace

std::string expand_output_pattern(const std::string& pattern, std::int64_t value) {
  int percents = 0;
  std::optional<Field> f = integer_field(pattern, &percents);
  if (!f) throw Error("internal: output pattern " + pattern + " has no single integer field");
  char number[32];
  std::snprintf(number, sizeof number, "%0*lld", f->width, static_cast<long long>(value));
  return pattern.substr(0, f->at) + number + pattern.substr(f->at + f->length);
}

RenderUnits plan_units(const RenderOptions& o, const SceneDescription& scene, std::uint32_t spp) {
  RenderUnits out;
  if (!o.frames.empty() && !o.spp_sweep.empty())
    throw UsageError("--frames " + o.frames + ": give --frames or --spp-sweep, not both");
  if (o.frame_time != 0.0 && o.frames.empty()) throw UsageError("--frame-time: only with --frames");
  int percents = 0;
  std::optional<Field> field = integer_field(o.output, &percents);
  const char* field_help = "one %d or %04d-style field";
  if (!o.frames.empty()) {
    out.kind = UnitKind::frames;
    std::size_t colon = o.frames.find(':');
    if (colon == std::string::npos) throw UsageError("--frames " + o.frames + ": expected A:B (first and last frame)");
    std::int64_t a = parse_integer(o.frames.substr(0, colon), "--frames", o.frames);
    std::int64_t b = parse_integer(o.frames.substr(colon + 1), "--frames", o.frames);
    if (a < 0 || b < a) throw UsageError("--frames " + o.frames + ": needs 0 <= A <= B");
    if (b - a >= 100000) throw UsageError("--frames " + o.frames + ": at most 100000 frames");
    if (!field)
      throw UsageError("--output " + o.output + ": with --frames the file name needs " + field_help + " for the frame number");
    if (!scene_moves(scene))
      throw UsageError("--frames " + o.frames + ": " + scene.source +
                       " has no moving object (\"motion\"): every frame would be the same image");
    const double open = scene.camera.shutter_open, close = scene.camera.shutter_close;
    out.frame_time = o.frame_time != 0.0 ? o.frame_time : close - open;
    if (!std::isfinite(o.frame_time) || o.frame_time < 0.0)
      throw UsageError("--frame-time " + std::to_string(o.frame_time) + ": must be positive");
    if (!(out.frame_time > 0.0))
      throw UsageError("--frames " + o.frames + ": the camera's shutter is empty (open = close), so frames need --frame-time");
    for (std::int64_t f = a; f <= b; ++f) {
      out.units.push_back({expand_output_pattern(o.output, f), f, spp});
      const double shift = static_cast<double>(f) * out.frame_time;
      try {
        check_motion(scene, float(open + shift), float(close + shift));
      } catch (const Error& e) {
        throw UsageError("--frames " + o.frames + ": frame " + std::to_string(f) + ": " + e.what());
      }
    }
  } else if (!o.spp_sweep.empty()) {
    out.kind = UnitKind::sweep;
    std::set<std::int64_t> seen;
    std::size_t start = 0;
    while (start <= o.spp_sweep.size()) {
      std::size_t comma = o.spp_sweep.find(',', start);
      std::string item = o.spp_sweep.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      std::int64_t v = parse_integer(item, "--spp-sweep", o.spp_sweep);
      if (v < 1 || v > 65536) throw UsageError("--spp-sweep " + o.spp_sweep + ": " + item + " is outside 1 .. 65536");
      if (!seen.insert(v).second) throw UsageError("--spp-sweep " + o.spp_sweep + ": " + item + " appears twice");
      out.units.push_back({"", 0, static_cast<std::uint32_t>(v)});
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (!field)
      throw UsageError("--output " + o.output + ": with --spp-sweep the file name needs " + field_help +
                       " for the samples per pixel");
    for (RenderUnit& u : out.units) u.output = expand_output_pattern(o.output, u.spp);
  } else {
    if (percents > 0 && field)
      throw UsageError("--output " + o.output + ": a %d field names several files, but neither --frames nor --spp-sweep is given");
    out.units.push_back({o.output, 0, spp});
  }
  for (const RenderUnit& u : out.units) check_image_output_flag(u.output);
  return out;
}

SceneDescription unit_scene(const SceneDescription& scene, const RenderUnits& units, const RenderUnit& unit) {
  if (units.kind != UnitKind::frames) return scene;
  SceneDescription s = scene;
  const double shift = static_cast<double>(unit.frame) * units.frame_time;
  s.camera.shutter_open = static_cast<float>(scene.camera.shutter_open + shift);
  s.camera.shutter_close = static_cast<float>(scene.camera.shutter_close + shift);
  return s;
}

}  // namespace rtcl::cli
