#include "ray_sets.hpp"

#include <algorithm>
#include <fstream>

#include "rtcl/error.hpp"

namespace rtcl::bench {

void write_preview(const std::string& path, const BenchScene& scene) {
  std::ofstream file(path, std::ios::binary);
  if (!file) throw Error("$RTCL_BENCH_DUMP: cannot write " + path);
  file << "P6\n" << scene.width << " " << scene.height << "\n255\n";
  std::size_t secondary = 0;
  const RaySet& primary = scene.primary;
  for (std::size_t i = 0; i < primary.rays.size(); ++i) {
    unsigned char rgb[3] = {40, 60, 110};
    const Hit& hit = primary.reference[i];
    if (hit.prim >= 0) {
      const glm::uvec3& tri = scene.geometry.triangles[static_cast<std::size_t>(hit.prim)];
      const auto& v = scene.geometry.vertices;
      glm::vec3 n = glm::normalize(glm::cross(v[tri.y] - v[tri.x], v[tri.z] - v[tri.x]));
      const Ray& r = primary.rays[i];
      float shade = std::abs(glm::dot(n, glm::vec3(r.dx, r.dy, r.dz)));
      bool shadowed = secondary < scene.shadow.reference.size() && scene.shadow.reference[secondary].prim >= 0;
      ++secondary;
      auto level = static_cast<unsigned char>(std::clamp(255.0f * (shadowed ? 0.35f : 1.0f) * shade, 0.0f, 255.0f));
      rgb[0] = rgb[1] = rgb[2] = level;
    }
    file.write(reinterpret_cast<const char*>(rgb), 3);
  }
}

}  // namespace rtcl::bench
