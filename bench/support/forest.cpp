#include "bench/support/forest.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace rtcl::bench {

namespace {

float spacing(const Aabb& bounds) { return 1.3f * std::max(bounds.extent().x, bounds.extent().z); }

std::size_t side(std::size_t count) {
  return static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(count))));
}

}  // namespace

std::vector<Transform> forest_placements(std::size_t count, const Aabb& bounds, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> turn(0.0f, 360.0f), size(0.8f, 1.2f);
  const glm::vec3 c = bounds.center();
  const float step = spacing(bounds);
  const std::size_t n = side(count);
  std::vector<Transform> out;
  out.reserve(count);
  for (std::size_t k = 0; k < count; ++k) {
    const float x = step * static_cast<float>(k % n), z = step * static_cast<float>(k / n);
    out.push_back(Transform::translate(x, 0, z) * Transform::rotate(turn(rng), 0, 1, 0) *
                  Transform::scale(size(rng)) * Transform::translate(-c.x, -c.y, -c.z));
  }
  return out;
}

Camera forest_camera(std::size_t count, const Aabb& bounds) {
  const float width = spacing(bounds) * static_cast<float>(side(count));
  return {{-0.1f * width, 0.3f * width, -0.1f * width}, {0.5f * width, 0.0f, 0.5f * width}, {0, 1, 0}, 50.0f};
}

std::vector<double> top_level_commit_ms(Scene& scene, const std::vector<InstanceId>& ids,
                                        const std::vector<Transform>& placements, int repeat) {
  std::vector<double> ms;
  for (int r = 0; r < repeat; ++r) {
    for (std::size_t k = 0; k < ids.size(); ++k) scene.set_transform(ids[k], placements[k]);
    ms.push_back(scene.commit().build_ms);
  }
  return ms;
}

}  // namespace rtcl::bench
