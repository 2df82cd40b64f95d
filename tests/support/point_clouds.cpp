#include "support/point_clouds.hpp"

#include <cmath>
#include <random>

namespace rtcl::test {

glm::dmat3 random_rotation(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  glm::dvec3 a(normal(rng), normal(rng), normal(rng)), b(normal(rng), normal(rng), normal(rng));
  a = glm::normalize(a);
  b = glm::normalize(b - glm::dot(a, b) * a);
  return glm::dmat3(a, b, glm::cross(a, b));
}

PointCloud uniform_cube(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  PointCloud c{"uniform cube", {}};
  for (std::size_t i = 0; i < n; ++i) c.points.emplace_back(u(rng), u(rng), u(rng));
  return c;
}

PointCloud uniform_ball(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  PointCloud c{"uniform ball", {}};
  while (c.points.size() < n) {
    glm::vec3 p(u(rng), u(rng), u(rng));
    if (glm::dot(p, p) <= 1.0f) c.points.push_back(p);
  }
  return c;
}

PointCloud clustered(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::normal_distribution<float> g(0.0f, 0.05f);
  std::vector<glm::vec3> centres;
  for (int k = 0; k < 8; ++k) centres.emplace_back(u(rng), u(rng), u(rng));
  PointCloud c{"clustered", {}};
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3& m = centres[i % centres.size()];
    c.points.emplace_back(m.x + g(rng), m.y + g(rng), m.z + g(rng));
  }
  return c;
}

PointCloud nearly_coplanar(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), thin(-1e-4, 1e-4);
  glm::dmat3 r = random_rotation(seed + 1);
  PointCloud c{"nearly coplanar", {}};
  for (std::size_t i = 0; i < n; ++i) c.points.emplace_back(r * glm::dvec3(u(rng), u(rng), thin(rng)));
  return c;
}

std::vector<PointCloud> random_clouds(std::size_t n, std::uint32_t seed) {
  return {uniform_cube(n, seed), uniform_ball(n, seed + 1), clustered(n, seed + 2), nearly_coplanar(n, seed + 3)};
}

}  // namespace rtcl::test
