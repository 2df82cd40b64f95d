#include "rtcl/beam/beam_cull.hpp"

#include <algorithm>
#include <cmath>

namespace rtcl::beam {

using glm::dvec3;
using glm::dvec4;

BeamFrustum beam_frustum(const ScreenSpace& screen, const Convex& section, const glm::dmat4& to_virtual,
                         const dvec4* keep_plane) {
  const CameraFrame& f = screen.frame;
  auto direction = [&](const glm::dvec2& xy) { return f.corner + xy.x * f.du + xy.y * f.dv; };
  glm::dvec2 mid(0.0);
  for (const glm::dvec2& p : section.v) mid += p;
  const dvec3 inside = direction(mid / double(section.v.size()));
  std::vector<dvec4> world;  // planes of the beam's world
  const std::size_t n = section.v.size();
  for (std::size_t i = 0; i < n; ++i) {
    dvec3 normal = glm::cross(direction(section.v[i]), direction(section.v[(i + 1) % n]));
    if (glm::dot(normal, inside) < 0.0) normal = -normal;
    const double len = glm::length(normal);
    if (!(len > 0.0)) continue;  // a degenerate edge bounds nothing
    normal /= len;
    world.push_back(dvec4(normal, -glm::dot(normal, f.origin)));
  }
  world.push_back(dvec4(screen.forward, -glm::dot(screen.forward, f.origin) - screen.near));
  if (keep_plane) world.push_back(*keep_plane);
  BeamFrustum out;
  const glm::dmat4 back = glm::transpose(to_virtual);
  for (const dvec4& L : world) out.planes.push_back(back * L);
  return out;
}

namespace {

// False when the box lies wholly on the negative side of the plane.
bool meets(const Aabb& box, const dvec4& L) {
  double best = L.w, magnitude = std::abs(L.w);
  for (int k = 0; k < 3; ++k) {
    const double lo = box.lower[k], hi = box.upper[k];
    best += L[k] * (L[k] > 0.0 ? hi : lo);
    magnitude += std::abs(L[k]) * std::max(std::abs(lo), std::abs(hi));
  }
  return best >= -1e-9 * magnitude;
}

}  // namespace

void cull(const BuildTree& bvh, const BeamFrustum& frustum, std::vector<std::uint32_t>& prims) {
  if (bvh.empty()) return;
  std::vector<std::uint32_t> stack{0};
  while (!stack.empty()) {
    const BuildNode& node = bvh.nodes[stack.back()];
    stack.pop_back();
    bool inside = true;
    for (const dvec4& L : frustum.planes)
      if (!meets(node.bounds, L)) {
        inside = false;
        break;
      }
    if (!inside) continue;
    if (node.is_leaf()) {
      prims.insert(prims.end(), bvh.prims.begin() + node.first, bvh.prims.begin() + node.first + node.count);
    } else {
      stack.push_back(node.child[0]);
      stack.push_back(node.child[1]);
    }
  }
}

}  // namespace rtcl::beam
