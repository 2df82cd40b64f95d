#include "bench_scenes.hpp"

#include <chrono>
#include <filesystem>

#include "cli_errors.hpp"
#include "rtcl/error.hpp"
#include "rtcl/scene/mesh_io.hpp"
#include "rtcl/scene/procedural.hpp"

namespace rtcl::cli {

namespace {

struct Procedural {
  const char* kind;
  const char* parameter;
  std::int64_t fallback, lowest, highest;  // limits: rtcl/scene/procedural.hpp
};
constexpr Procedural procedurals[] = {
    {"sphereflake", "levels", 3, 0, 7},
    {"tetra", "levels", 6, 0, 11},
    {"mount", "levels", 6, 0, 11},
    {"soup", "count", 100000, 1, std::int64_t{1} << 26},
    {"surface", "count", 1000000, 18, std::int64_t{1} << 26},
};

const Procedural* find_procedural(const std::string& kind) {
  for (const Procedural& p : procedurals)
    if (kind == p.kind) return &p;
  return nullptr;
}

}  // namespace

std::vector<std::string> split_spec_list(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t comma = text.find(',', start);
    std::string piece = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (!out.empty() && piece.find(':') == std::string::npos && piece.find('=') != std::string::npos)
      out.back() += "," + piece;
    else
      out.push_back(piece);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

std::string bench_scene_names() {
  std::string out;
  for (const bench::SceneSpec& s : bench::scene_specs()) out += (out.empty() ? "" : ", ") + s.name;
  for (const Procedural& p : procedurals)
    out += std::string(", ") + p.kind + ":" + p.parameter + "=N";
  return out;
}

BenchSceneSpec parse_bench_scene(const std::string& text, const std::string& scenes_dir) {
  std::string context = "--scene " + text;
  BenchSceneSpec spec;
  std::size_t colon = text.find(':');
  spec.kind = text.substr(0, colon);
  std::string parameters = colon == std::string::npos ? "" : text.substr(colon + 1);
  if (const bench::SceneSpec* shared = bench::find_scene_spec(spec.kind)) {
    if (!parameters.empty()) throw UsageError(context + ": the mesh scene " + spec.kind + " takes no parameters");
    if (scenes_dir.empty())
      throw UsageError(context + ": a mesh scene, and no scenes directory is given: pass --scenes-dir DIR or set "
                       "RTCL_SCENES_DIR to the directory that holds " + shared->file);
    spec.file = scenes_dir + "/" + shared->file;
    if (!std::filesystem::is_regular_file(spec.file))
      throw Error(context + ": mesh file " + spec.file + " not found (--scenes-dir or $RTCL_SCENES_DIR names the "
                  "scenes directory)");
    spec.text = spec.kind;
    return spec;
  }
  const Procedural* p = find_procedural(spec.kind);
  if (!p) throw UsageError(context + ": unknown scene '" + spec.kind + "' (known: " + bench_scene_names() + ")");
  spec.size = p->fallback;
  if (!parameters.empty()) {
    std::string key = parameters.substr(0, parameters.find('='));
    if (key != p->parameter || parameters.find('=') == std::string::npos)
      throw UsageError(context + ": " + spec.kind + " takes one parameter, " + p->parameter + "=N");
    std::string value = parameters.substr(key.size() + 1);
    std::size_t used = 0;
    long long n = 0;
    try {
      n = std::stoll(value, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != value.size() || n < p->lowest || n > p->highest)
      throw UsageError(context + ": " + p->parameter + " must be an integer in [" + std::to_string(p->lowest) + ", " +
                  std::to_string(p->highest) + "], not '" + value + "'");
    spec.size = n;
  }
  spec.text = spec.kind + ":" + p->parameter + "=" + std::to_string(spec.size);
  return spec;
}

LoadedBenchScene load_bench_scene(const BenchSceneSpec& spec) {
  auto start = std::chrono::steady_clock::now();
  LoadedBenchScene scene;
  scene.spec = spec;
  const bench::SceneSpec* shared = bench::find_scene_spec(spec.kind);
  if (shared) {
    scene.geometry = load_mesh(spec.file).geometry;
    if (shared->stadium > 0.0f) add_stadium(scene.geometry, shared->stadium);
  } else if (spec.kind == "sphereflake") {
    scene.geometry = sphereflake(static_cast<int>(spec.size));
  } else if (spec.kind == "tetra") {
    scene.geometry = sierpinski_tetrahedron(static_cast<int>(spec.size));
  } else if (spec.kind == "mount") {
    scene.geometry = fractal_mountain(static_cast<int>(spec.size));
  } else if (spec.kind == "surface") {
    scene.geometry = tessellated_surface(static_cast<std::size_t>(spec.size));
  } else {
    scene.geometry = random_triangle_soup(static_cast<std::size_t>(spec.size));
  }
  scene.geometry.source = spec.text;
  validate(scene.geometry);
  if (shared && !shared->fit) {
    scene.camera = shared->camera;
    scene.light = shared->light;
  } else {
    Aabb bounds = scene.geometry.bounds();
    scene.camera = bench::fit_camera(bounds);
    scene.light = bench::fit_light(bounds);
  }
  scene.load_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return scene;
}

}  // namespace rtcl::cli
