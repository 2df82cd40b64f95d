// Mesh import (OBJ with MTL, PLY, STL) through Assimp.
//
// Triangle order, which fixes primitive ids: objects in the order the file
// declares them (for OBJ: the order of their first face; a new object starts
// at each `o`/`g` or material change), and within an object faces in file
// order; a polygon with k vertices becomes the fan (v0, vj, vj+1),
// j = 1 .. k-2, in that order. Points and lines are ignored.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/scene/geometry.hpp"

namespace rtcl {

// A material as the mesh file states it (MTL: Ka, Kd, Ks, Ke, Ns, Ni, d).
struct MeshMaterial {
  std::string name;
  glm::vec3 ambient{0.0f}, diffuse{0.8f}, specular{0.0f}, emission{0.0f};
  float shininess = 0.0f;
  float ior = 1.0f;
  float opacity = 1.0f;  // MTL d: 1 is opaque
};

struct MeshObject {
  std::string name;
  std::size_t first_triangle = 0, triangle_count = 0;
  std::uint32_t material = 0;  // index into LoadedMesh::materials
};

struct LoadedMesh {
  Geometry geometry;  // source = the file path; no spheres
  std::vector<MeshObject> objects;
  std::vector<MeshMaterial> materials;  // at least one (a default grey)
  std::vector<std::uint32_t> triangle_material;  // one per triangle
};

// Throws Error naming the path for a missing or unreadable file, an unknown
// format, a parse error, or a file with no triangles. Geometry is not
// validated here (call validate()).
LoadedMesh load_mesh(const std::string& path);

}  // namespace rtcl
