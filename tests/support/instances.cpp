#include "support/instances.hpp"

namespace rtcl::test {

glm::dvec3 apply(const Transform& transform, const glm::dvec3& p) {
  glm::dvec3 out;
  for (int row = 0; row < 3; ++row) {
    const auto& m = transform.m[row];
    out[row] = double{m[0]} * p.x + double{m[1]} * p.y + double{m[2]} * p.z + double{m[3]};
  }
  return out;
}

Transform blend(const Transform& open, const Transform& close, double time) {
  Transform t;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 4; ++col)
      t.m[row][col] = static_cast<float>((1.0 - time) * open.m[row][col] + time * close.m[row][col]);
  return t;
}

FlatInstances flatten_instances(const Geometry& mesh, const std::vector<Transform>& transforms) {
  FlatInstances flat;
  flat.geometry.source = mesh.source + " (instances, flattened)";
  for (const Transform& t : transforms) {
    const auto base = static_cast<std::uint32_t>(flat.geometry.vertices.size());
    flat.first.push_back(static_cast<std::uint32_t>(flat.geometry.triangles.size()));
    Aabb box;
    for (const glm::vec3& v : mesh.vertices) {
      flat.geometry.vertices.push_back(glm::vec3(apply(t, glm::dvec3(v))));
      box.grow(flat.geometry.vertices.back());
    }
    flat.boxes.push_back(box);
    for (const glm::uvec3& tri : mesh.triangles) flat.geometry.triangles.push_back(tri + glm::uvec3(base));
  }
  return flat;
}

Hit flat_hit(const FlatInstances& flat, std::uint32_t instance, const Hit& hit) {
  Hit out = hit;
  if (hit.prim >= 0) out.prim = static_cast<std::int32_t>(flat.first.at(instance) + static_cast<std::uint32_t>(hit.prim));
  return out;
}

}  // namespace rtcl::test
