// rtcl.render: `rtcl render`'s single image as a numpy array (H, W, 3)
// float32, linear RGB, rows from the top. The options are the command's
// (docs/cli.md, src/cli/render_command.cpp) under Python names; the scene is
// a built-in scene's name or a scene file.
#include <pybind11/stl.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "array_io.hpp"
#include "devices.hpp"
#include "rtcl/accel_options.hpp"
#include "rtcl/beam/beam_renderer.hpp"
#include "rtcl/error.hpp"
#include "rtcl/precision.hpp"
#include "rtcl/render/camera.hpp"
#include "rtcl/render/image.hpp"
#include "rtcl/render/renderer.hpp"
#include "rtcl/render/sampling_options.hpp"
#include "rtcl/render/selective.hpp"
#include "rtcl/render/wavelet.hpp"
#include "rtcl/scene/scene_file.hpp"
#include "rtcl/scene/scene_lights.hpp"
#include "rtcl/scene/showcase_scene.hpp"

namespace rtcl::python {

namespace {

struct RenderArgs {
  long long width = 512, height = 0, spp = 1, depth = 5, seed = 0, light_samples = 1, batch = 1 << 17;
  double min_weight = 1e-3;
  std::string sampler = "stratified", filter = "box", method = "ray", beam_order = "exact";
  long long selective_block = 8;
  double selective_threshold = 0.05, selective_depth = 0.1, wavelet_budget = 0.25;
  std::optional<std::string> accel, precision;
};

[[noreturn]] void bad(const std::string& param, const std::string& value, const std::string& rule) {
  throw py::value_error("render: " + param + " is " + value + "; must be " + rule);
}

void check_int(const char* param, long long v, long long lo, long long hi) {
  if (v < lo || v > hi) bad(param, std::to_string(v), "in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

void check_real(const char* param, double v, bool ok, const char* rule) {
  if (!ok || std::isnan(v)) bad(param, std::to_string(v), rule);
}

void check_args(const RenderArgs& a) {
  check_int("width", a.width, 1, 65536);
  if (a.height != 0) check_int("height", a.height, 1, 65536);
  check_int("spp", a.spp, 1, 65536);
  check_int("depth", a.depth, 0, 64);
  check_int("seed", a.seed, 0, 0xffffffffll);
  check_int("light_samples", a.light_samples, 1, 4096);
  check_int("batch", a.batch, 1, 1 << 26);
  check_int("selective_block", a.selective_block, 1, 256);
  check_real("min_weight", a.min_weight, a.min_weight >= 0.0 && a.min_weight <= 1.0, "in [0, 1]");
  check_real("selective_threshold", a.selective_threshold,
             a.selective_threshold >= 0.0 && std::isfinite(a.selective_threshold), "a finite number >= 0");
  check_real("selective_depth", a.selective_depth, a.selective_depth >= 0.0 && std::isfinite(a.selective_depth),
             "a finite number >= 0");
  check_real("wavelet_budget", a.wavelet_budget, a.wavelet_budget > 0.0 && a.wavelet_budget <= 1.0, "in (0, 1]");
  if (!sampler_from_name(a.sampler)) bad("sampler", "'" + a.sampler + "'", "one of " + sampler_names());
  if (!filter_from_name(a.filter)) bad("filter", "'" + a.filter + "'", "one of " + filter_names());
  if (a.method != "ray" && a.method != "selective" && a.method != "wavelet" && a.method != "beam")
    bad("method", "'" + a.method + "'", "one of ray, selective, wavelet, beam");
  if (a.beam_order != "exact" && a.beam_order != "key") bad("beam_order", "'" + a.beam_order + "'", "exact or key");
}

// The library's errors about an argument, as ValueError.
template <class Fn>
auto as_value_error(Fn&& fn) {
  try {
    return fn();
  } catch (const Error& e) {
    throw py::value_error(e.what());
  }
}

// None: the built-in default scene; "default", "showcase" or "forest": that
// built-in scene (the forest's bunny from $RTCL_SCENES_DIR, as rtcl render
// reads it); anything else (a str or an os.PathLike): a scene file.
SceneDescription read_scene(py::handle scene) {
  if (scene.is_none()) return builtin_scene("default");
  std::string path;
  if (py::isinstance<py::str>(scene)) {
    path = scene.cast<std::string>();
    if (path == "default" || path == "showcase" || path == "forest") {
      const char* scenes_dir = std::getenv("RTCL_SCENES_DIR");
      return as_value_error([&] { return builtin_scene(path, scenes_dir ? scenes_dir : ""); });
    }
  } else if (py::hasattr(scene, "__fspath__")) {
    path = py::str(scene.attr("__fspath__")()).cast<std::string>();
  } else {
    throw py::type_error("render: scene must be None, a built-in scene's name or a scene file path, got " +
                         py::str(py::type::of(scene).attr("__name__")).cast<std::string>());
  }
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw py::value_error("render: scene \"" + path + "\": no such file (built-in scenes: default, showcase, forest)");
  return as_value_error([&] { return load_scene(path); });
}

Image render_image(const Device& device, const SceneDescription& scene, const RenderArgs& a) {
  RenderSettings settings;
  settings.width = static_cast<std::uint32_t>(a.width);
  settings.height = a.height > 0 ? static_cast<std::uint32_t>(a.height) : default_height(scene.camera, settings.width);
  settings.max_depth = static_cast<std::uint32_t>(a.depth);
  settings.spp = static_cast<std::uint32_t>(a.spp);
  settings.min_weight = static_cast<float>(a.min_weight);
  settings.batch_pixels = static_cast<std::uint32_t>(a.batch);
  settings.sampler = *sampler_from_name(a.sampler);
  settings.filter = *filter_from_name(a.filter);
  settings.seed = static_cast<std::uint32_t>(a.seed);
  settings.light_samples = static_cast<std::uint32_t>(a.light_samples);
  AccelConfig config;
  config.precision = a.precision ? as_value_error([&] { return parse_precision(*a.precision); })
                                 : scene.precision.value_or(Precision::robust);
  const std::string accel = a.accel ? *a.accel : !scene.accel.empty() ? scene.accel : "bvh";
  as_value_error([&] {
    parse_accel_spec(accel);
    require_precision(device.info(), config.precision);
    return 0;
  });

  py::gil_scoped_release release;
  if (a.method == "beam") {
    as_value_error([&] {
      beam::check_beam_scene(scene);
      return 0;
    });
    beam::BeamSettings bs;
    bs.width = settings.width;
    bs.height = settings.height;
    bs.order = a.beam_order == "key" ? beam::DepthOrder::key : beam::DepthOrder::exact;
    bs.accel = accel;
    bs.max_depth = settings.max_depth;
    bs.min_weight = settings.min_weight;
    return beam::render_beam(device, scene, bs);
  }
  std::unique_ptr<Renderer> renderer;
  try {
    renderer = std::make_unique<Renderer>(device, scene, accel, config);
  } catch (const Error& e) {
    // The structure or the scene refused (a moving scene needs "bvh"):
    // arguments; anything else is the device's.
    const std::string what = e.what();
    for (const char* prefix : {"Renderer accel", "make_accel name", "precision"})
      if (what.rfind(prefix, 0) == 0) throw py::value_error(what);
    throw;
  }
  if (a.method == "selective") {
    SelectiveSettings s;
    s.block = static_cast<std::uint32_t>(a.selective_block);
    s.threshold = static_cast<float>(a.selective_threshold);
    s.depth_threshold = static_cast<float>(a.selective_depth);
    return render_selective(*renderer, settings, s);
  }
  if (a.method == "wavelet") {
    WaveletSettings s;
    s.block = static_cast<std::uint32_t>(a.selective_block);
    s.budget = static_cast<float>(a.wavelet_budget);
    return render_wavelet(*renderer, settings, s);
  }
  return renderer->render(settings);
}

}  // namespace

void bind_render(py::module_& m) {
  m.def(
      "render",
      [](py::handle scene_arg, long long width, py::object height, long long spp, long long depth,
         const std::string& sampler, long long seed, const std::string& filter, long long light_samples,
         double min_weight, const std::string& method, long long selective_block, double selective_threshold,
         double selective_depth, double wavelet_budget, const std::string& beam_order, std::optional<std::string> accel,
         std::optional<std::string> precision, py::handle device, long long batch) {
        RenderArgs a;
        a.width = width;
        a.height = height.is_none() ? 0 : height.cast<long long>();
        if (!height.is_none() && a.height == 0) bad("height", "0", "in [1, 65536] (None: from the camera's aspect)");
        a.spp = spp;
        a.depth = depth;
        a.sampler = sampler;
        a.seed = seed;
        a.filter = filter;
        a.light_samples = light_samples;
        a.min_weight = min_weight;
        a.method = method;
        a.selective_block = selective_block;
        a.selective_threshold = selective_threshold;
        a.selective_depth = selective_depth;
        a.wavelet_budget = wavelet_budget;
        a.beam_order = beam_order;
        a.accel = std::move(accel);
        a.precision = std::move(precision);
        a.batch = batch;
        check_args(a);
        SceneDescription scene = read_scene(scene_arg);
        // A scene without lights is lit as `rtcl render` lights it.
        const LightNotice lights = default_lights(scene, a.method != "beam", "method=\"beam\"");
        py::object warn = py::module_::import("warnings").attr("warn");
        for (const std::string& note : scene.notes) warn("rtcl: note: " + note);
        if (!lights.note.empty()) warn("rtcl: note: " + lights.note);
        if (!lights.warning.empty()) warn("rtcl: warning: " + lights.warning);
        const Device opened = open_device(device);
        const Image image = render_image(opened, scene, a);
        auto out =
            output_array<float>({static_cast<py::ssize_t>(image.height), static_cast<py::ssize_t>(image.width)}, {3});
        std::copy(image.rgb.begin(), image.rgb.end(), out.mutable_data());
        return out;
      },
      py::arg("scene") = py::none(), py::arg("width") = 512, py::arg("height") = py::none(), py::arg("spp") = 1,
      py::kw_only(), py::arg("depth") = 5, py::arg("sampler") = "stratified", py::arg("seed") = 0,
      py::arg("filter") = "box", py::arg("light_samples") = 1, py::arg("min_weight") = 1e-3, py::arg("method") = "ray",
      py::arg("selective_block") = 8, py::arg("selective_threshold") = 0.05, py::arg("selective_depth") = 0.1,
      py::arg("wavelet_budget") = 0.25, py::arg("beam_order") = "exact", py::arg("accel") = py::none(),
      py::arg("precision") = py::none(), py::arg("device") = py::none(), py::arg("batch") = 1 << 17,
      R"doc(Renders a scene as `rtcl render` does and returns the image: (height, width, 3)
float32, linear RGB, row 0 at the top.

scene: None (the built-in default scene), "default", "showcase" or "forest"
    (built-in scenes; the forest reads its bunny from $RTCL_SCENES_DIR), or
    the path of a scene file (JSON, docs/file-formats.md).
width, height: pixels (height None: width / the camera's aspect).
spp: samples per pixel. depth: reflection/refraction bounces.
sampler: "stratified", "random" or "sobol"; seed: of every sample pattern.
filter: "box" or "gaussian". light_samples: shadow rays per area light.
min_weight: secondary rays below this path weight are dropped.
method: "ray" (every pixel), "selective" (selective_block,
    selective_threshold, selective_depth), "wavelet" (selective_block,
    wavelet_budget) or "beam" (beam_order: "exact" or "key").
accel, precision: the structure and level (default: the scene file's, else
    "bvh" and "robust"). device: as RaycastingScene's. batch: camera rays per
    wavefront.
A scene that declares no light is lit by its emissive triangles, as
`rtcl render` lights it (docs/cli.md, "Scenes without lights"); notes and
warnings about the scene come as Python warnings.)doc");
}

}  // namespace rtcl::python
