#include "support/fixtures.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <algorithm>
#include <random>
#include <string>

#include "rtcl/scene/mesh_io.hpp"

namespace rtcl::test {

Geometry bunny() {
  static const Geometry loaded = [] {
    Geometry g = load_mesh(scene_path("stanford_bunny/bunny.obj")).geometry;
    validate(g);
    return g;
  }();
  return loaded;
}

bool same_bits(const Hit& a, const Hit& b) { return std::memcmp(&a, &b, sizeof(Hit)) == 0; }

bool same_bits(const std::vector<Hit>& a, const std::vector<Hit>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(Hit)) == 0);
}

bool has(const std::vector<std::string>& defines, const std::string& define) {
  return std::find(defines.begin(), defines.end(), define) != defines.end();
}

Geometry sine_deformed(Geometry g, float amplitude, float waves) {
  const Aabb box = g.bounds();
  const glm::vec3 extent = box.extent();
  const float size = std::max({extent.x, extent.y, extent.z});
  const float k = 2.0f * 3.14159265f * waves / size;
  for (glm::vec3& v : g.vertices) {
    const glm::vec3 p = v - box.lower;
    v += amplitude * size * glm::vec3(std::sin(k * p.y), std::sin(k * p.z + 1.0f), std::sin(k * p.x + 2.0f));
  }
  g.source += ", sine-deformed";
  return g;
}

Ray make_ray(glm::vec3 o, glm::vec3 d, float tmin, float tmax) {
  return {o.x, o.y, o.z, d.x, d.y, d.z, tmin, tmax};
}

const Device& test_device() {
  static const Device device = [] {
    try {
      return Device::open();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "FATAL: the tests need an OpenCL device: %s\n", e.what());
      std::abort();
    }
  }();
  return device;
}

std::vector<std::string> tested_structures() {
  std::vector<std::string> names = accel_names();
  names.push_back("bvh:presplit=1");
  return names;
}

std::vector<Precision> test_precisions() {
  static const std::vector<Precision> levels = [] {
    std::vector<Precision> chosen = {Precision::robust, Precision::exact, Precision::fast};
    if (const char* list = std::getenv("RTCL_TEST_PRECISIONS")) {
      chosen.clear();
      std::string text = list;
      for (std::size_t begin = 0; begin <= text.size();) {
        std::size_t end = std::min(text.find(',', begin), text.size());
        std::string name = text.substr(begin, end - begin);
        try {
          chosen.push_back(parse_precision(name));
        } catch (const std::exception& e) {
          std::fprintf(stderr, "FATAL: RTCL_TEST_PRECISIONS=%s: %s\n", list, e.what());
          std::abort();
        }
        begin = end + 1;
      }
    }
    std::vector<Precision> supported;
    for (Precision p : chosen)
      if (precision_unsupported(test_device().info(), p).empty()) supported.push_back(p);
    return supported;
  }();
  return levels;
}

std::string scenes_dir() {
  const char* dir = std::getenv("RTCL_SCENES_DIR");
  return dir && *dir ? dir : RTCL_SCENE_DIR;
}

std::string scene_path(const std::string& relative) { return scenes_dir() + "/" + relative; }

Geometry with_a_degenerate_triangle() {
  Geometry g;
  g.source = "two triangles and a degenerate one";
  g.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 0, 0}, {3, 0, 0}, {4, 0, 0}};
  g.triangles = {{0, 1, 2}, {1, 3, 2}, {4, 5, 6}};
  return g;
}

Geometry triangle_fan(int count) {
  Geometry g;
  g.source = "fan of " + std::to_string(count) + " triangles";
  g.vertices.push_back({0.0f, 0.0f, 0.0f});
  for (int i = 0; i < count; ++i) {
    double a = 2.0 * M_PI * i / count;
    g.vertices.push_back({static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)), 0.0f});
  }
  for (int i = 0; i < count; ++i)
    g.triangles.push_back({0u, static_cast<std::uint32_t>(1 + i), static_cast<std::uint32_t>(1 + (i + 1) % count)});
  return g;
}

Geometry random_soup(std::size_t count, std::uint32_t seed, float size, float scale, glm::vec3 offset) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), centred(-0.5f, 0.5f);
  Geometry g;
  g.source = "random soup";
  for (std::size_t i = 0; i < count; ++i) {
    glm::vec3 c(unit(rng), unit(rng), unit(rng));
    for (int k = 0; k < 3; ++k) {
      glm::vec3 v = c + size * glm::vec3(centred(rng), centred(rng), centred(rng));
      g.vertices.push_back(v * scale + offset);
    }
    auto base = static_cast<std::uint32_t>(3 * i);
    g.triangles.push_back({base, base + 1, base + 2});
  }
  return g;
}

std::vector<Ray> random_rays(const Geometry& geometry, std::size_t count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  Aabb box = geometry.bounds();
  glm::vec3 c = box.center();
  float radius = glm::length(box.extent());
  std::vector<Ray> rays;
  for (std::size_t i = 0; i < count; ++i) {
    glm::vec3 dir_out = glm::normalize(glm::vec3(normal(rng), normal(rng), normal(rng)));
    glm::vec3 o = c + radius * dir_out;
    glm::vec3 target = box.lower + box.extent() * glm::vec3(unit(rng), unit(rng), unit(rng));
    glm::vec3 d = target - o;
    rays.push_back({o.x, o.y, o.z, d.x, d.y, d.z, 0.0f, std::numeric_limits<float>::infinity()});
  }
  return rays;
}

std::vector<Hit> run_query(const Accel& accel, const std::vector<Ray>& rays, Query query, Coherence coherence) {
  const Device& device = accel.device();
  cl::Buffer ray_buffer = device.upload(rays.data(), rays.size() * sizeof(Ray), "test rays");
  cl::Buffer hit_buffer = device.allocate(rays.size() * sizeof(Hit), "test hits");
  std::vector<Hit> hits(rays.size());
  with_cl_errors([&] {
    cl::Event done = accel.trace(query, ray_buffer, hit_buffer, rays.size(), {}, coherence);
    std::vector<cl::Event> wait{done};
    device.queue().enqueueReadBuffer(hit_buffer, CL_TRUE, 0, hits.size() * sizeof(Hit), hits.data(), &wait);
  });
  return hits;
}

}  // namespace rtcl::test
