#include "rtcl/scene/mesh_io.hpp"

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "rtcl/error.hpp"
#include "support/fixtures.hpp"
#include "support/temp_dir.hpp"

namespace rtcl::test {
namespace {

using Triangle = std::array<glm::vec3, 3>;

Triangle corners(const Geometry& g, std::size_t t) {
  return {g.vertices[g.triangles[t].x], g.vertices[g.triangles[t].y], g.vertices[g.triangles[t].z]};
}

const MeshMaterial& material_of(const LoadedMesh& m, std::size_t triangle) {
  return m.materials.at(m.triangle_material.at(triangle));
}

// The message of the Error that load_mesh throws ("" when it does not throw).
std::string load_error(const std::string& path) {
  try {
    load_mesh(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// Two objects, two materials, quads, a pentagon, negative indices and v//vn
// references. Expected fan triangles are listed with the test.
const char* const two_objects_obj = R"(# two objects, two materials
mtllib two.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 2 0 0
v 3 1 0
v 2 2 0
v 1 3 0
v 0 2 1
v 5 5 5
v 6 5 5
v 6 6 5
vn 0 0 1
o first
usemtl red
f 1 2 3 4
f 2//1 5//1 3//1
usemtl blue
f 5 6 7 8 9
o second
f -3 -2 -1
usemtl red
f 10 12 11 1
)";

const char* const two_materials_mtl = R"(newmtl red
Ka 0.1 0.0 0.0
Kd 0.9 0.1 0.1
Ks 0.5 0.5 0.5
Ke 0 0 0
Ns 32
Ni 1.5
d 0.75
newmtl blue
Kd 0.1 0.1 0.9
Ke 2 3 4
)";

TEST(MeshIo, ObjOrderIsFileOrderWithFansAcrossObjectsAndMaterials) {
  TempDir dir;
  dir.write("two.mtl", two_materials_mtl);
  LoadedMesh m = load_mesh(dir.write("two.obj", two_objects_obj));
  const glm::vec3 v[] = {{0, 0, 0}, {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}, {3, 1, 0},
                         {2, 2, 0}, {1, 3, 0}, {0, 2, 1}, {5, 5, 5}, {6, 5, 5}, {6, 6, 5}};  // 1-based
  const Triangle expected[] = {
      {v[1], v[2], v[3]},    {v[1], v[3], v[4]},                        // quad 1 2 3 4
      {v[2], v[5], v[3]},                                               // triangle 2 5 3
      {v[5], v[6], v[7]},    {v[5], v[7], v[8]},   {v[5], v[8], v[9]},  // pentagon 5 6 7 8 9
      {v[10], v[11], v[12]},                                            // -3 -2 -1
      {v[10], v[12], v[11]}, {v[10], v[11], v[1]},                      // quad 10 12 11 1
  };
  ASSERT_EQ(m.geometry.triangles.size(), std::size(expected));
  for (std::size_t t = 0; t < std::size(expected); ++t)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(corners(m.geometry, t)[k], expected[t][k]) << "triangle " << t << " corner " << k;
  EXPECT_EQ(m.geometry.vertices.size(), 12u) << "equal positions share one vertex";
  EXPECT_EQ(m.geometry.source, dir.file("two.obj"));

  const char* materials[] = {"red", "red", "red", "blue", "blue", "blue", "blue", "red", "red"};
  ASSERT_EQ(m.triangle_material.size(), std::size(materials));
  for (std::size_t t = 0; t < std::size(materials); ++t) EXPECT_EQ(material_of(m, t).name, materials[t]) << t;

  struct Expected {
    const char* name;
    std::size_t first, count;
    const char* material;
  } objects[] = {{"first", 0, 3, "red"}, {"first", 3, 3, "blue"}, {"second", 6, 1, "blue"}, {"second", 7, 2, "red"}};
  ASSERT_EQ(m.objects.size(), std::size(objects));
  for (std::size_t i = 0; i < std::size(objects); ++i) {
    EXPECT_EQ(m.objects[i].name, objects[i].name) << i;
    EXPECT_EQ(m.objects[i].first_triangle, objects[i].first) << i;
    EXPECT_EQ(m.objects[i].triangle_count, objects[i].count) << i;
    EXPECT_EQ(m.materials.at(m.objects[i].material).name, objects[i].material) << i;
  }
  EXPECT_TRUE(m.notes.empty()) << m.notes.front();
}

TEST(MeshIo, MtlFieldsReachMeshMaterial) {
  TempDir dir;
  dir.write("two.mtl", two_materials_mtl);
  LoadedMesh m = load_mesh(dir.write("two.obj", two_objects_obj));
  const MeshMaterial& red = material_of(m, 0);
  EXPECT_EQ(red.ambient, glm::vec3(0.1f, 0.0f, 0.0f));
  EXPECT_EQ(red.diffuse, glm::vec3(0.9f, 0.1f, 0.1f));
  EXPECT_EQ(red.specular, glm::vec3(0.5f));
  EXPECT_EQ(red.emission, glm::vec3(0.0f));
  EXPECT_FLOAT_EQ(red.shininess, 32.0f);
  EXPECT_FLOAT_EQ(red.ior, 1.5f);
  EXPECT_FLOAT_EQ(red.opacity, 0.75f);
  const MeshMaterial& blue = material_of(m, 3);
  EXPECT_EQ(blue.diffuse, glm::vec3(0.1f, 0.1f, 0.9f));
  EXPECT_EQ(blue.emission, glm::vec3(2.0f, 3.0f, 4.0f));
  EXPECT_FLOAT_EQ(blue.ior, 1.0f);
  EXPECT_FLOAT_EQ(blue.opacity, 1.0f);
}

TEST(MeshIo, CornellBoxHasEightObjectsAndAnEmissiveLight) {
  LoadedMesh m = load_mesh(scene_path("cornell_box/CornellBox-Original.obj"));
  EXPECT_EQ(m.geometry.triangles.size(), 36u);
  ASSERT_EQ(m.objects.size(), 8u);
  EXPECT_EQ(m.objects.front().name, "floor");
  EXPECT_EQ(m.objects.back().name, "light");
  const MeshMaterial& light = m.materials.at(m.objects.back().material);
  EXPECT_EQ(light.name, "light");
  EXPECT_EQ(light.emission, glm::vec3(17.0f, 12.0f, 4.0f));
  EXPECT_EQ(material_of(m, 0).name, "floor");
  EXPECT_TRUE(m.notes.empty());
}

// --- the claim "OBJ triangles follow the file's face order", on real files ---

struct ObjScan {
  std::vector<Triangle> triangles;  // fans of the f lines, file order
  std::vector<std::string> usemtl;  // names in file order
  std::vector<std::string> groups;  // g names in file order
};

// A deliberately plain OBJ reader: v and f lines only (f tokens v, v/t, v//n,
// v/t/n; negative indices relative to the vertices read so far).
ObjScan scan_obj(const std::string& path) {
  std::string text = read_text(path);
  ObjScan scan;
  std::vector<glm::vec3> vertices;
  for (std::size_t pos = 0; pos < text.size();) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(pos, end - pos);
    pos = end + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.rfind("v ", 0) == 0) {
      glm::vec3 p;
      char* cursor = line.data() + 2;
      for (int k = 0; k < 3; ++k) p[k] = std::strtof(cursor, &cursor);
      vertices.push_back(p);
    } else if (line.rfind("f ", 0) == 0) {
      std::vector<glm::vec3> face;
      char* cursor = line.data() + 1;
      while (true) {
        char* before = cursor;
        long index = std::strtol(cursor, &cursor, 10);
        if (cursor == before) break;
        while (*cursor && *cursor != ' ' && *cursor != '\t') ++cursor;  // skip /t/n
        face.push_back(vertices.at(index > 0 ? index - 1 : vertices.size() + index));
      }
      for (std::size_t k = 1; k + 1 < face.size(); ++k) scan.triangles.push_back({face[0], face[k], face[k + 1]});
    } else if (line.rfind("usemtl ", 0) == 0) {
      scan.usemtl.push_back(line.substr(7));
    } else if (line.rfind("g ", 0) == 0) {
      scan.groups.push_back(line.substr(2));
    }
  }
  return scan;
}

void expect_file_order(const LoadedMesh& m, const ObjScan& scan) {
  ASSERT_EQ(m.geometry.triangles.size(), scan.triangles.size());
  std::size_t mismatches = 0, first = 0;
  for (std::size_t t = 0; t < scan.triangles.size(); ++t) {
    Triangle got = corners(m.geometry, t);
    for (int k = 0; k < 3; ++k)
      for (int axis = 0; axis < 3; ++axis) {
        float a = got[k][axis], b = scan.triangles[t][k][axis];
        if (std::abs(a - b) > 1e-6f * std::max(1.0f, std::abs(b)) && mismatches++ == 0) first = t;
      }
  }
  EXPECT_EQ(mismatches, 0u) << "first differing triangle: " << first;
}

TEST(MeshIo, SponzaGroupsKeepFileOrder) {
  std::string path = scene_path("sponza/sponza.obj");
  auto start = std::chrono::steady_clock::now();
  LoadedMesh m = load_mesh(path);
  double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf("load_mesh(sponza.obj, 7.6 MB): %.0f ms\n", ms);
  ObjScan scan = scan_obj(path);
  EXPECT_EQ(scan.triangles.size(), 66454u);
  expect_file_order(m, scan);
  // Objects: the named groups that hold faces, in file order.
  std::vector<std::string> names;
  for (const auto& o : m.objects) names.push_back(o.name);
  std::vector<std::string> groups;
  for (const auto& g : scan.groups)
    if (!g.empty() && g.find_first_not_of(' ') != std::string::npos) groups.push_back(g);
  EXPECT_EQ(names, groups);
  EXPECT_TRUE(m.notes.empty());
}

TEST(MeshIo, SibenikMaterialsKeepFileOrder) {
  std::string path = scene_path("sibenik/sibenik.obj");
  LoadedMesh m = load_mesh(path);
  ObjScan scan = scan_obj(path);
  EXPECT_EQ(scan.triangles.size(), 73564u);
  expect_file_order(m, scan);
  std::vector<std::string> run_materials;
  for (const auto& o : m.objects) run_materials.push_back(m.materials.at(o.material).name);
  EXPECT_EQ(run_materials, scan.usemtl);
  EXPECT_EQ(scan.usemtl.size(), 14u);
  for (const auto& o : m.objects) EXPECT_EQ(o.name, "sibenik");
}

// --- Assimp quirks: pinned, so that a changed Assimp shows up here ----------

TEST(MeshIo, ReusedObjectNameIsReportedAndMovesFaces) {
  TempDir dir;
  dir.write("two.mtl", two_materials_mtl);
  std::string path = dir.write("reuse.obj",
                               "mtllib two.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                               "o A\nusemtl red\nf 1 2 3\no B\nf 2 3 4\no A\nusemtl blue\nf 3 4 1\n");
  LoadedMesh m = load_mesh(path);
  ASSERT_EQ(m.geometry.triangles.size(), 3u);
  // File order would be (1 2 3), (2 3 4), (3 4 1); Assimp files the third
  // face under the earlier object A, before B.
  EXPECT_EQ(corners(m.geometry, 1)[0], glm::vec3(1, 1, 0));
  EXPECT_EQ(corners(m.geometry, 2)[0], glm::vec3(1, 0, 0));
  ASSERT_EQ(m.notes.size(), 1u);
  EXPECT_NE(m.notes[0].find("line 11 reuses the object name 'A'"), std::string::npos) << m.notes[0];
  EXPECT_NE(m.notes[0].find(path), std::string::npos);
}

TEST(MeshIo, FacesBeforeFirstUsemtlGetTheLastMaterialAndANote) {
  TempDir dir;
  dir.write("two.mtl", two_materials_mtl);
  std::string path =
      dir.write("early.obj", "mtllib two.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nusemtl red\nf 1 3 2\n");
  LoadedMesh m = load_mesh(path);
  EXPECT_EQ(material_of(m, 0).name, "blue");  // the MTL's last material
  EXPECT_EQ(material_of(m, 1).name, "red");
  ASSERT_EQ(m.notes.size(), 1u);
  EXPECT_NE(m.notes[0].find("1 face comes before the first usemtl"), std::string::npos) << m.notes[0];
}

// --- PLY and STL ----------------------------------------------------------

TEST(MeshIo, PlyPolygonsInFileOrder) {
  TempDir dir;
  std::string path = dir.write("quad.ply",
                               "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
                               "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
                               "0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n4 0 1 2 3\n3 1 4 2\n");
  LoadedMesh m = load_mesh(path);
  ASSERT_EQ(m.geometry.triangles.size(), 3u);
  EXPECT_EQ(m.geometry.triangles[0], glm::uvec3(0, 1, 2));
  EXPECT_EQ(m.geometry.triangles[1], glm::uvec3(0, 2, 3));
  EXPECT_EQ(m.geometry.triangles[2], glm::uvec3(1, 4, 2));
  EXPECT_EQ(m.geometry.vertices[4], glm::vec3(2, 0, 0));
  EXPECT_EQ(m.objects.size(), 1u);
  EXPECT_GE(m.materials.size(), 1u);
}

TEST(MeshIo, StlSharesEqualVertices) {
  TempDir dir;
  std::string path = dir.write("two.stl",
                               "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                               "endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 1 1 0\n"
                               "vertex 0 1 0\nendloop\nendfacet\nendsolid t\n");
  LoadedMesh m = load_mesh(path);
  ASSERT_EQ(m.geometry.triangles.size(), 2u);
  EXPECT_EQ(m.geometry.vertices.size(), 4u);
  EXPECT_EQ(corners(m.geometry, 1)[1], glm::vec3(1, 1, 0));
}

TEST(MeshIo, ZeroAreaTrianglesKeepTheirIds) {
  TempDir dir;
  LoadedMesh m = load_mesh(dir.write("flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\nf 3 2 1\n"));
  ASSERT_EQ(m.geometry.triangles.size(), 3u);
  EXPECT_EQ(validate(m.geometry).zero_area_triangles, 1u);
  EXPECT_TRUE(zero_area(m.geometry, 1));
}

// --- errors -----------------------------------------------------------------

void expect_error(const std::string& path, const std::string& fragment) {
  std::string message = load_error(path);
  ASSERT_FALSE(message.empty()) << path << " loaded without error";
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_NE(message.find(fragment), std::string::npos) << message;
}

const char* const triangle_v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

TEST(MeshIoErrors, MissingFileDirectoryAndExtension) {
  TempDir dir;
  expect_error(dir.file("absent.obj"), "no such mesh file");
  expect_error(dir.path(), "is a directory");
  expect_error(dir.write("scene.fbx", "x"), "unsupported mesh format '.fbx'");
  expect_error(dir.write("scene", "x"), "unsupported mesh format '(no extension)'");
  EXPECT_EQ(load_error(dir.write("upper.OBJ", std::string(triangle_v) + "f 1 2 3\n")), "");
}

TEST(MeshIoErrors, AssimpParseFailuresCarryAssimpsMessage) {
  TempDir dir;
  expect_error(dir.write("letters.obj", std::string(triangle_v) + "f 1 2 x\n"), "Invalid face index");
  expect_error(dir.write("tiny.obj", "v"), "cannot import mesh: OBJ-file is too small");
  expect_error(dir.write("broken.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0\n"), "cannot import mesh");
}

// Checked before Assimp reads the file (scene/mesh_precheck.hpp).
TEST(MeshIoErrors, EmptyFilesAndNonPlyHeaders) {
  TempDir dir;
  for (const char* name : {"empty.obj", "empty.ply", "empty.stl"}) expect_error(dir.write(name, ""), "the file is empty");
  expect_error(dir.write("junk.ply", "this is not a ply file at all\n"), "not a PLY file (the first line is not 'ply')");
}

TEST(MeshIoErrors, OutOfRangeIndices) {
  TempDir dir;
  expect_error(dir.write("far.obj", std::string(triangle_v) + "f 1 2 9\n"), "vertex index out of range");
  expect_error(dir.write("back.obj", std::string(triangle_v) + "f 1 2 -9\n"), "vertex index out of range");
  expect_error(dir.write("zero.obj", std::string(triangle_v) + "f 0 1 2\n"), "Invalid face index");
  // Assimp's PLY reader passes bad indices through; rtcl catches them.
  expect_error(dir.write("far.ply",
                         "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                         "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                         "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"),
               "uses vertex index 7, but the object has only 3 vertices");
}

TEST(MeshIoErrors, NonFiniteCoordinatesNameTheTriangle) {
  TempDir dir;
  for (const char* bad : {"nan", "inf", "-inf", "1e39"}) {
    std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 " + std::string(bad) + " 0\nf 1 2 3\nf 1 2 4\n";
    expect_error(dir.write("bad.obj", text), "triangle 1 (object 'defaultobject') has a NaN or infinite vertex");
  }
  // An unused non-finite vertex is harmless: no triangle refers to it.
  EXPECT_EQ(load_error(dir.write("unused.obj", std::string(triangle_v) + "v nan 0 0\nf 1 2 3\n")), "");
}

TEST(MeshIoErrors, NoTriangles) {
  TempDir dir;
  expect_error(dir.write("points.obj", std::string(triangle_v) + "p 1\nl 1 2 3\n"), "no triangles");
  expect_error(dir.write("vertices.obj", triangle_v), "no triangles");
  expect_error(dir.write("noise.obj", "this is a text file\nbut not a mesh\n"), "no triangles");
}

}  // namespace
}  // namespace rtcl::test
