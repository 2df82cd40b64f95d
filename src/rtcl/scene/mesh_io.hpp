// Mesh import (OBJ with MTL, PLY, STL) through Assimp.
//
// Primitive ids (triangle order):
// - Every polygon with k >= 3 vertices becomes the fan (v0, vj, vj+1),
//   j = 1 .. k-2, in that order (polygons are assumed convex and planar).
//   Points, lines and faces with fewer than 3 vertices are ignored.
// - OBJ: triangles follow the file's face order, whatever its objects,
//   groups and materials (but see the quirks below). Assimp starts a new
//   object at each `o` with a new name and each `g` that changes the group,
//   and a new mesh at each `usemtl` that changes the material, and keeps them
//   all in file order; checked against a plain scan of the `f` lines of
//   sponza (groups) and sibenik (materials) in tests/mesh_io_test.cpp.
// - Other files: Assimp's node tree depth-first (a node's meshes, then its
//   children), faces in each mesh's order; for PLY and STL files with one
//   mesh that is the file's face order. Node transforms are applied.
// Vertices with exactly equal coordinates are shared (one index), so vertex
// ids are not the file's vertex numbers.
//
// Assimp 5.2 quirks, kept and reported in LoadedMesh::notes when a file
// triggers them:
// - an `o NAME` that reuses an earlier object or group name does not start a
//   new object: later faces join the current mesh, and a material change then
//   adds a mesh to the EARLIER object, so those faces move before the objects
//   in between (ids no longer follow the file's face order);
// - in a file with `mtllib`, faces before the first `usemtl` get the LAST
//   material of the MTL file instead of a default one.
// A `usemtl` naming a material missing from the MTL (or a missing MTL file)
// silently gives a material with Assimp's defaults (grey).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/geometry.hpp"

namespace rtcl {

// A material as the mesh file states it (MTL: Ka, Kd, Ks, Ke, Ns, Ni, d).
// Fields the file does not state keep these defaults; Assimp fills OBJ
// materials with its own (Kd 0.6 grey, Ns 0, Ni 1, d 1).
struct MeshMaterial {
  std::string name;
  glm::vec3 ambient{0.0f}, diffuse{0.8f}, specular{0.0f}, emission{0.0f};
  float shininess = 0.0f;  // MTL Ns (Phong exponent)
  float ior = 1.0f;        // MTL Ni
  float opacity = 1.0f;    // MTL d (or 1 - Tr): 1 is opaque
};

// A contiguous run of triangles with one name and one material: for OBJ, one
// per `o`/`g` object and material run within it, in file order.
struct MeshObject {
  std::string name;  // the OBJ object/group name ("defaultobject" before any)
  std::size_t first_triangle = 0, triangle_count = 0;
  std::uint32_t material = 0;  // index into LoadedMesh::materials
};

struct LoadedMesh {
  Geometry geometry;                // source = the file path; no spheres; indices in range, coordinates finite
  std::vector<MeshObject> objects;  // cover all triangles, in id order, none empty
  // All materials Assimp reports, in its order (unused ones included; for OBJ,
  // index 0 is Assimp's "DefaultMaterial"); at least one.
  std::vector<MeshMaterial> materials;
  std::vector<std::uint32_t> triangle_material;  // one per triangle
  // Things the user should know about this file (the Assimp quirks above,
  // when the file triggers them), each naming the path; load_mesh never
  // prints, callers show them.
  std::vector<std::string> notes;
};

// Throws Error naming the path for a missing or unreadable file, an
// extension other than .obj/.ply/.stl (any case), an Assimp import failure
// (with Assimp's message), a face with an out-of-range vertex index, a NaN or
// infinite coordinate in a vertex some triangle uses (naming the triangle),
// or a file with no triangles. Zero-area triangles are kept (they hold their
// ids); validate(mesh.geometry) counts them.
LoadedMesh load_mesh(const std::string& path);

}  // namespace rtcl
