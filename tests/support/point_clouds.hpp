// Random point sets for the bounding-volume tests and benchmark: the shapes
// the lecture's claims are measured on, plus the degenerate ones.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace rtcl::test {

struct PointCloud {
  std::string name;
  std::vector<glm::vec3> points;
};

// n points, fixed seed:
//   uniform cube   [-1, 1]^3
//   uniform ball   |p| <= 1
//   clustered      8 Gaussian clusters (sigma 0.05) at random centres in [-1, 1]^3
//   nearly coplanar  [-1, 1]^2 x [-1e-4, 1e-4], rotated
PointCloud uniform_cube(std::size_t n, std::uint32_t seed);
PointCloud uniform_ball(std::size_t n, std::uint32_t seed);
PointCloud clustered(std::size_t n, std::uint32_t seed);
PointCloud nearly_coplanar(std::size_t n, std::uint32_t seed);

// The four above, each with n points.
std::vector<PointCloud> random_clouds(std::size_t n, std::uint32_t seed);

// A rotation taking the world axes to a random orthonormal basis.
glm::dmat3 random_rotation(std::uint32_t seed);

}  // namespace rtcl::test
