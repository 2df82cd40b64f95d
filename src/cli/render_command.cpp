// `rtcl render [scene.json] -o out.png`: Whitted ray tracing on an OpenCL
// device. Without a scene file it renders the built-in default scene.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "accel_option.hpp"
#include "commands.hpp"
#include "distributed.hpp"
#include "flag_names.hpp"
#include "option_checks.hpp"
#include "progress.hpp"
#include "rates.hpp"
#include "render_options.hpp"
#include "render_units.hpp"
#include "rtcl/scene/scene_lights.hpp"
#include "rtcl/accel.hpp"
#include "rtcl/beam/beam_renderer.hpp"
#include "rtcl/device.hpp"
#include "rtcl/error.hpp"
#include "rtcl/render/camera.hpp"
#include "rtcl/render/image.hpp"
#include "rtcl/render/renderer.hpp"
#include "rtcl/render/sampling_options.hpp"
#include "rtcl/render/selective.hpp"
#include "rtcl/render/wavelet.hpp"
#include "rtcl/scene/default_scene.hpp"
#include "rtcl/scene/scene_file.hpp"
#include "rtcl/scene/showcase_scene.hpp"

namespace rtcl::cli {

namespace {

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& i : items) out += (out.empty() ? "-D" : " -D") + i;
  return out;
}

// --method beam: the scene refused before the device is opened when it has
// spheres or area lights.
void run_beam(const RenderOptions& o) {
  check_image_extension_flag(o.output);
  SceneDescription scene = load_render_scene(o);
  beam::check_beam_scene(scene);
  check_image_output_flag(o.output);
  RenderPlan plan = plan_render(o, scene);
  Device device = open_device_flag(o.device);
  beam::BeamSettings bs;
  bs.width = plan.settings.width;
  bs.height = plan.settings.height;
  bs.order = o.beam_order == "key" ? beam::DepthOrder::key : beam::DepthOrder::exact;
  bs.accel = plan.accel;
  bs.max_depth = plan.settings.max_depth;
  bs.min_weight = plan.settings.min_weight;
  beam::BeamStats st;
  Image image = beam::render_beam(device, scene, bs, &st);
  write_image(o.output, image);
  std::printf("rtcl render: %s (%ux%u, beam tracing, %s depth order, exact pixel coverage, reflection and "
              "refraction beams to depth %u (refraction linearised, one M_t per beam), candidates by BVH frustum cull, "
              "point-light shadows by shadow rays through %s, %s): %zu polygons, %zu tile beams of 8x8 px + %zu "
              "reflected + %zu refracted beams in %u levels, %zu candidates, %zu fragments, %zu pixel pieces, %zu "
              "shadow rays in %.3f s (clipping kernels %.1f ms, candidate cull %.1f ms)\n",
              o.output.c_str(), bs.width, bs.height, o.beam_order.c_str(), bs.max_depth, bs.accel.c_str(),
              device.info().name.c_str(), st.polygons, st.tiles, st.reflected_beams, st.refracted_beams, st.levels,
              st.candidates, st.fragments, st.pixel_pieces, st.shadow_rays, st.render_ms * 1e-3, st.clip_ms,
              st.cull_ms);
}

// --method selective | wavelet: the image, and its summary line.
Image render_sparse(const RenderOptions& o, const RenderPlan& plan, Renderer& renderer) {
  SelectiveStats stats;
  Image image;
  if (o.method == "selective") {
    SelectiveSettings s;
    s.block = o.selective_block;
    s.threshold = o.selective_threshold;
    s.depth_threshold = o.selective_depth;
    image = render_selective(renderer, plan.settings, s, &stats);
  } else {
    WaveletSettings s;
    s.block = o.selective_block;
    s.budget = o.wavelet_budget;
    try {
      image = render_wavelet(renderer, plan.settings, s, &stats);
    } catch (const Error& e) {
      // A budget below what the coarse pass of this image traces: the flag's value.
      const std::string what = e.what(), setting = "wavelet budget ";
      if (what.rfind(setting, 0) != 0 || what.find(": ") == std::string::npos) throw;
      char value[32];
      std::snprintf(value, sizeof value, "%g", static_cast<double>(o.wavelet_budget));
      throw UsageError("--wavelet-budget " + std::string(value) + what.substr(what.find(": ")));
    }
  }
  const double pixels = double(plan.settings.width) * plan.settings.height;
  std::printf("rtcl render: %s: traced %llu of %.0f pixels (%.1f%%) in %u batches, %llu rays, %.3f s\n",
              o.method.c_str(), (unsigned long long)stats.traced_pixels, pixels, 100.0 * stats.traced_pixels / pixels,
              stats.launches, (unsigned long long)stats.rays.total(), stats.render_ms * 1e-3);
  return image;
}

void run(const RenderOptions& o) {
  check_image_extension_flag(o.output);  // the command line before any file is read
  if (launcher_world_size() && o.method != "ray")
    throw UsageError("--method " + o.method + ": not under mpirun (only --method ray renders with ranks)");
  if (o.method == "beam") {
    if (!o.frames.empty() || !o.spp_sweep.empty())
      throw UsageError(std::string(o.frames.empty() ? "--spp-sweep" : "--frames") +
                       ": not with --method beam (it renders one static image)");
    if (!o.accel.empty()) parse_accel_flag(o.accel);
    return run_beam(o);
  }
  if (launcher_world_size()) {
    refuse_ranks_without_mpi("rtcl render");
    if (mpi_supported()) return render_distributed(o);
  }
  if (!o.accel.empty()) parse_accel_flag(o.accel);  // before the scene is loaded
  SceneDescription scene = load_render_scene(o);
  RenderPlan plan = plan_render(o, scene);
  RenderUnits units = plan_units(o, scene, plan.settings.spp);  // checks the output paths before the long work
  Device device = open_device_flag(o.device);
  require_precision_flag(device.info(), plan.config.precision);
  std::unique_ptr<Renderer> renderer;
  for (const RenderUnit& unit : units.units) {
    // A frame is a scene of its own (its shutter interval), except on the
    // two-level path, where the frame's shutter re-places the moving
    // objects (the top level is rebuilt, no mesh); a sweep's images share
    // the renderer.
    if (renderer && units.kind == UnitKind::frames && renderer->instanced()) {
      const Camera& camera = unit_scene(scene, units, unit).camera;
      CommitStats commit = renderer->set_shutter(camera.shutter_open, camera.shutter_close);
      if (o.verbose)
        std::printf("rtcl render: frame %lld: %zu bottom levels built, top level %s\n", (long long)unit.frame,
                    commit.bottom_levels_built, commit.top_level_built ? "rebuilt" : "kept");
    } else if (!renderer || units.kind == UnitKind::frames)
      // A structure given by --accel is named so in the renderer's errors.
      renderer = naming_accel_flag(o.accel, [&] {
        return std::make_unique<Renderer>(device, unit_scene(scene, units, unit), plan.accel, plan.config);
      });
    if (o.verbose && renderer->instanced() && unit.output == units.units.front().output) {
      const SceneStats st = renderer->scene()->stats();
      std::printf("rtcl render: two-level scene: %zu meshes, %zu instances, %zu bottom levels built, %.1f MiB "
                  "structure + %.1f MiB shading records on the device\n",
                  st.meshes, st.instances, st.bottom_levels_built, st.device_bytes / 1048576.0,
                  renderer->shading_bytes() / 1048576.0);
    }
    RenderPlan unit_plan = plan;
    unit_plan.settings.spp = unit.spp;
    if (o.method != "ray") {
      write_image(unit.output, render_sparse(o, unit_plan, *renderer));
      continue;
    }
    Progress progress("rendering", o.quiet);
    Image image = renderer->render(unit_plan.settings, [&](double f) { progress.bar(f); });
    progress.clear();
    write_image(unit.output, image);
    RenderOptions unit_options = o;
    unit_options.output = unit.output;
    print_render_summary(unit_options, unit_plan, device.info().name, renderer->stats(), renderer->defines());
    if (o.verbose)
      std::printf("rtcl render: %s: %.2f MiB of device buffers held\n", unit.output.c_str(),
                  device.allocated_bytes() / 1048576.0);
  }
}

SceneDescription read_scene_with_lights(const RenderOptions& o, LightNotice* notice) {
  if (!o.scene.empty() && !o.builtin.empty())
    throw UsageError("--builtin " + o.builtin + ": give a scene file or a built-in scene, not both (scene file " +
                     o.scene + ")");
  SceneDescription scene = o.scene.empty() ? builtin_scene_flag(o.builtin.empty() ? "default" : o.builtin) : load_scene(o.scene);
  *notice = default_lights(scene, o.method != "beam");
  return scene;
}

}  // namespace

SceneDescription read_render_scene(const RenderOptions& o) {
  LightNotice ignored;
  return read_scene_with_lights(o, &ignored);
}

SceneDescription load_render_scene(const RenderOptions& o) {
  LightNotice notice;
  SceneDescription scene = read_scene_with_lights(o, &notice);
  for (const std::string& note : scene.notes) std::fprintf(stderr, "rtcl: note: %s\n", note.c_str());
  if (!notice.note.empty()) std::fprintf(stderr, "rtcl: note: %s\n", notice.note.c_str());
  if (!notice.warning.empty()) std::fprintf(stderr, "rtcl: warning: %s\n", notice.warning.c_str());
  return scene;
}

RenderPlan plan_render(const RenderOptions& o, const SceneDescription& scene) {
  RenderPlan plan;
  RenderSettings& settings = plan.settings;
  settings.width = o.width;
  settings.height = o.height > 0 ? o.height : default_height(scene.camera, o.width);
  settings.max_depth = o.depth;
  settings.spp = o.spp;
  settings.min_weight = o.min_weight;
  settings.batch_pixels = o.batch;
  settings.sampler = *sampler_from_name(o.sampler);  // checked by the option's validator
  settings.filter = *filter_from_name(o.filter);
  settings.seed = o.seed;
  settings.light_samples = o.light_samples;
  plan.config.precision =
      !o.precision.empty() ? parse_precision_flag(o.precision) : scene.precision.value_or(Precision::robust);
  plan.accel = !o.accel.empty() ? o.accel : !scene.accel.empty() ? scene.accel : default_accel();
  return plan;
}

void print_render_summary(const RenderOptions& o, const RenderPlan& plan, const std::string& devices,
                          const RenderStats& st, const std::vector<std::string>& defines) {
  const RenderSettings& settings = plan.settings;
  const RayCounts& r = st.rays;
  std::printf("rtcl render: %s (%ux%u, %u spp %s seed %u, %s filter, %u light samples, depth %u, %s, %s precision, "
              "%s): %llu camera + %llu shadow + %llu reflection + %llu refraction = %llu rays in %.3f s, %s Mrays/s "
              "(trace only: camera %s, shadow %s, secondary %s Mrays/s)\n",
              o.output.c_str(), settings.width, settings.height, settings.spp, o.sampler.c_str(), settings.seed,
              o.filter.c_str(), settings.light_samples, settings.max_depth, plan.accel.c_str(),
              std::string(precision_name(plan.config.precision)).c_str(), devices.c_str(),
              (unsigned long long)r.camera, (unsigned long long)r.shadow, (unsigned long long)r.reflection,
              (unsigned long long)r.refraction, (unsigned long long)r.total(), st.render_ms * 1e-3,
              mrays_text(double(r.total()), st.render_ms).c_str(), mrays_text(double(r.camera), st.camera_trace_ms).c_str(),
              mrays_text(double(r.shadow), st.shadow_trace_ms).c_str(),
              mrays_text(double(r.reflection + r.refraction), st.secondary_trace_ms).c_str());
  if (o.verbose)
    std::printf("rtcl render: device ms: generate %.1f, trace camera %.1f, shade %.1f, compact %.1f, trace shadow "
                "%.1f, trace secondary %.1f, accumulate %.1f; %u generations, largest queue %zu rays, queues %.1f "
                "MiB; kernels specialised with %s\n",
                st.generate_ms, st.camera_trace_ms, st.shade_ms, st.compact_ms, st.shadow_trace_ms,
                st.secondary_trace_ms, st.accumulate_ms, st.generations, st.peak_queue, st.queue_bytes / 1048576.0,
                join(defines).c_str());
}

void add_render_command(CLI::App& app) {
  auto o = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand(
      "render", "Whitted and distributed ray tracing (reflection, refraction, hard and soft shadows, "
                "anti-aliasing, depth of field, glossy reflection, motion blur) of a scene file, or of a built-in "
                "scene when none is given; animations (--frames) and sample sweeps (--spp-sweep)");
  cmd->add_option("scene", o->scene, "Scene file (JSON, docs/file-formats.md); none: a built-in scene (--builtin)");
  cmd->add_option("--builtin", o->builtin,
                  "Built-in scene when no scene file is given: default (Whitted: mirror, glass, hard shadows) | "
                  "showcase (area light, glossy, glass, depth of field, motion blur) | forest (10,000 instances of "
                  "the Stanford bunny from $RTCL_SCENES_DIR, a few of them moving)")
      ->check(one_of({"default", "showcase", "forest"}, "built-in scene"));
  cmd->add_option("-o,--output", o->output,
                  "Output image; the extension picks the format: " + image_formats_text() +
                      "; with --frames or --spp-sweep a pattern with one %d or %04d field")
      ->capture_default_str();
  add_accel_option(*cmd, o->accel);
  cmd->add_option("--precision", o->precision,
                  "fast | robust | exact: the trace kernels' precision level and the spawn offsets (default: the "
                  "scene file's \"precision\", else robust; docs/precision.md)")
      ->check(one_of(precision_names(), "precision level"));
  add_device_option(*cmd, o->device, "$RTCL_DEVICE, else device 0; under mpirun, each rank's own (docs/cli.md)");
  cmd->add_option("--width", o->width, "Image width in pixels")->capture_default_str()->check(integer_in(1, 65536));
  cmd->add_option("--height", o->height, "Image height in pixels (default: width / the camera's aspect)")
      ->check(integer_in(1, 65536));
  cmd->add_option("--depth", o->depth, "Reflection/refraction bounces after the first hit (speed/accuracy)")
      ->capture_default_str()
      ->check(integer_in(0, 64));
  cmd->add_option("--spp", o->spp, "Samples per pixel (anti-aliasing; each carries its own lens, light and glossy "
                                    "samples) (speed/accuracy)")
      ->capture_default_str()
      ->check(integer_in(1, 65536));
  cmd->add_option("--sampler", o->sampler,
                  "Sample pattern: " + sampler_names() +
                      " (stratified: jittered strata, one sample = the pixel centre; random: independent; sobol: "
                      "Owen-scrambled Sobol)")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](const std::string& name) {
            return sampler_from_name(name) ? std::string() : "unknown sampler (known: " + sampler_names() + ")";
          },
          "NAME"));
  cmd->add_option("--seed", o->seed, "Seed of every sample pattern (the image is a function of it)")
      ->capture_default_str()
      ->check(integer_in(0, 4294967295LL));
  cmd->add_option("--filter", o->filter, "Reconstruction filter: " + filter_names() + " (gaussian: sigma 0.5 px, radius 1.5 px)")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](const std::string& name) {
            return filter_from_name(name) ? std::string() : "unknown filter (known: " + filter_names() + ")";
          },
          "NAME"));
  cmd->add_option("--light-samples", o->light_samples,
                  "Shadow rays per area light and shading point (soft shadows; speed/accuracy)")
      ->capture_default_str()
      ->check(integer_in(1, 4096));
  cmd->add_option("--min-weight", o->min_weight,
                  "Drop secondary rays whose path weight is below this (speed/accuracy; 0 keeps all)")
      ->capture_default_str()
      ->check(number_where("a number in [0, 1]", [](double v) { return v >= 0.0 && v <= 1.0; }));
  cmd->add_option("--method", o->method,
                  "ray: trace every pixel; selective: trace block corners, subdivide blocks whose corners differ, "
                  "interpolate the rest; wavelet: a coarse pass, then whole blocks where its Haar coefficients are "
                  "large, under --wavelet-budget (speed/accuracy); beam: beam tracing with reflection beams to --depth "
                  "(polygons, point lights and mirrors only; exact pixel coverage, --spp and the samplers do not "
                  "apply)")
      ->capture_default_str()
      ->check(one_of({"ray", "selective", "wavelet", "beam"}, "method"));
  cmd->add_option("--selective-block", o->selective_block,
                  "selective, wavelet: side of the first blocks in pixels (1 traces every pixel) (speed/accuracy)")
      ->capture_default_str()
      ->check(integer_in(1, 256));
  auto finite_non_negative = [](double v) { return v >= 0.0 && std::isfinite(v); };
  cmd->add_option("--selective-threshold", o->selective_threshold,
                  "selective: a block is interpolated only when its corners' display values (clamped to [0, 1]) "
                  "span less than this per channel, they hit the same material, and their depths agree (0 traces "
                  "every pixel) (speed/accuracy)")
      ->capture_default_str()
      ->check(number_where("a finite number >= 0", finite_non_negative));
  cmd->add_option("--selective-depth", o->selective_depth,
                  "selective: ... and their first-hit distances span at most this fraction of the nearest")
      ->capture_default_str()
      ->check(number_where("a finite number >= 0", finite_non_negative));
  cmd->add_option("--wavelet-budget", o->wavelet_budget,
                  "wavelet: pixels traced in all, coarse pass included, as a fraction of the image's, in (0, 1] "
                  "(speed/accuracy)")
      ->capture_default_str()
      ->check(number_where("in (0, 1]", [](double v) { return v > 0.0 && v <= 1.0; }));
  cmd->add_option("--frames", o->frames,
                  "Animation: render frames A:B of a scene with moving objects; frame f's shutter is the camera's "
                  "moved by f * --frame-time; the output needs a %d or %04d field for the frame number");
  cmd->add_option("--frame-time", o->frame_time,
                  "With --frames: keyframe time from one frame to the next (default: the shutter's length)")
      ->check(number_where("a finite number > 0", [](double v) { return v > 0.0 && std::isfinite(v); }));
  cmd->add_option("--spp-sweep", o->spp_sweep,
                  "One image per samples-per-pixel value, e.g. 1,4,16; the output needs a %d field for the value");
  cmd->add_option("--batch", o->batch, "Camera rays per wavefront (device memory vs parallelism)")
      ->capture_default_str()
      ->check(integer_in(1, 1 << 26));
  cmd->add_option("--tile", o->tile,
                  "Under mpirun: tile side in pixels, handed out one at a time by rank 0 (a multiple of 8)")
      ->capture_default_str()
      ->check(integer_in(8, 65536))
      ->check(CLI::Validator(
          [](std::string& text) {
            return std::stoul(text) % 8 == 0 ? std::string()
                                             : std::string("must be a multiple of 8 (the renderer's 8x8 ray order)");
          },
          "multiple of 8"));
  cmd->add_option("--tile-order", o->tile_order,
                  "Under mpirun: the order tiles are handed out in: rows | shuffled (the image is the same)")
      ->capture_default_str()
      ->check(one_of({"rows", "shuffled"}, "tile order"));
  cmd->add_option("--scene-from", o->scene_from,
                  "Under mpirun: root (rank 0 reads the scene and broadcasts it, meshes included) | each (every "
                  "rank reads the file itself, e.g. from a shared file system)")
      ->capture_default_str()
      ->check(one_of({"root", "each"}, "scene source"));
  cmd->add_option("--beam-order", o->beam_order,
                  "With --method beam: exact (a fragment gives up where a later polygon is nearer) | key (the walk "
                  "in nearest-point order alone; wrong for interpenetrating polygons)")
      ->capture_default_str()
      ->check(one_of({"exact", "key"}, "beam order"));
  add_quiet_flag(*cmd, o->quiet);
  cmd->add_flag("-v,--verbose", o->verbose, "Also print the device time of each stage and the queue sizes");
  cmd->callback([o] { run(*o); });
}

}  // namespace rtcl::cli
