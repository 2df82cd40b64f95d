// The size checks made before Assimp reads a mesh accept every well-formed
// file, at the tightest sizes, and name what a malformed one declares
// (scene/mesh_precheck.hpp; whole-tool runs: malformed_files_test.cpp).
#include "rtcl/scene/mesh_precheck.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "support/error_of.hpp"

namespace rtcl::test {
namespace {

using namespace std::string_literals;

const std::string header =
    "ply\r\nformat ascii 1.0\ncomment c\nobj_info o\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

TEST(MeshPrecheck, TightWellFormedFilesPass) {
  // single digits and no final newline: the fewest bytes an ASCII body can have
  EXPECT_EQ(error_of([] { check_declared_sizes("a.ply", ".ply", header + "0 0 0 1 0 0 0 1 0 3 0 1 2"); }), "");
  std::string stl(80, 's');  // a binary header may start with anything but "solid"
  stl += "\x01\x00\x00\x00"s;
  stl.append(50, '\0');
  EXPECT_EQ(error_of([&] { check_declared_sizes("a.stl", ".stl", stl); }), "");
  EXPECT_EQ(error_of([] { check_declared_sizes("a.stl", ".stl", "  solid x\nendsolid x\n"); }), "");
  EXPECT_EQ(error_of([] { check_declared_sizes("a.obj", ".obj", "v"); }), "");
}

TEST(MeshPrecheck, MalformedFilesNameWhatTheyDeclare) {
  std::string e = error_of([] { check_declared_sizes("a.ply", ".ply", header + "0 0 0 1 0 0 0 1 0 3 0 1"); });
  EXPECT_NE(e.find("a.ply: PLY element 'face' 0 of 1: a list declares 3 entries, but only 4 bytes remain"), std::string::npos) << e;
  e = error_of([] { check_declared_sizes("a.ply", ".ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty half x\n"
                                                           "end_header\n"); });
  EXPECT_NE(e.find("a.ply: PLY header line 4: unknown property type 'half'"), std::string::npos) << e;
  e = error_of([] { check_declared_sizes("a.ply", ".ply", "ply\nformat ascii 1.0\nelement vertex 3\n"); });
  EXPECT_NE(e.find("the file ends before 'end_header'"), std::string::npos) << e;
  e = error_of([] { check_declared_sizes("a.stl", ".stl", std::string(83, 'x')); });
  EXPECT_NE(e.find("a.stl: 83 bytes: neither an ASCII STL"), std::string::npos) << e;
  EXPECT_NE(error_of([] { check_declared_sizes("a.obj", ".obj", ""); }).find("a.obj: the file is empty"),
            std::string::npos);
}

// Assimp 5.2 skips header lines it does not know (Blender writes "Created
// by Blender3D ..." without "comment"), and ends an element's properties at
// the first other line, ignoring property lines after it.
TEST(MeshPrecheck, UnknownHeaderLinesAreSkippedAsAssimpSkipsThem) {
  const std::string body = "0 0 0 1 0 0 0 1 0 3 0 1 2";
  const std::string blender =
      "ply\nformat ascii 1.0\nCreated by Blender3D 247 - www.blender.org, source file: \nproperty float w\n"
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nobj_info o\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  EXPECT_EQ(error_of([&] { check_declared_sizes("a.ply", ".ply", blender + body); }), "");
  // the skipped lines declare nothing: the sizes are still checked
  std::string e = error_of([&] { check_declared_sizes("a.ply", ".ply", blender + "0 0 0 1 0 0 0 1 0 3 0 1"); });
  EXPECT_NE(e.find("a.ply: PLY element 'face' 0 of 1: a list declares 3 entries"), std::string::npos) << e;
  for (const char* between : {"comment c\n", "obj_info o\n", "Created by x\n"}) {
    std::string split = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n" + std::string(between) +
                        "property float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
    e = error_of([&] { check_declared_sizes("a.ply", ".ply", split); });
    EXPECT_NE(e.find("a.ply: PLY header line 6: a property of element 'vertex' after a line that is not a property"),
              std::string::npos)
        << between << ": " << e;
  }
}

// Assimp 5.2 sizes an element's arrays by its first declaration and
// writes a second declaration's instances past their end (valgrind: an
// invalid write just after the 36-byte block of three vertices, and after
// the 24-byte block of one face's indices; found by
// fuzz/mesh_loader_fuzz.cpp): a name declared twice is refused, whatever
// the counts.
TEST(MeshPrecheck, AnElementDeclaredTwiceIsRefused) {
  const std::string xyz = "property float x\nproperty float y\nproperty float z\n";
  const std::string twice = "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz + "element vertex 6\n" + xyz +
                            "end_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 0\n1 0 1\n0 1 1\n1 1 1\n2 2 2\n";
  std::string e = error_of([&] { check_declared_sizes("a.ply", ".ply", twice); });
  EXPECT_NE(e.find("a.ply: PLY header line 7: element 'vertex' is declared a second time"), std::string::npos) << e;
  const std::string faces = "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz +
                            "element face 1\nproperty list uchar int vertex_indices\n"
                            "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                            "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n";
  e = error_of([&] { check_declared_sizes("a.ply", ".ply", faces); });
  EXPECT_NE(e.find("a.ply: PLY header line 9: element 'face' is declared a second time"), std::string::npos) << e;
  // distinct names, the same counts: accepted
  EXPECT_EQ(error_of([&] {
              check_declared_sizes("a.ply", ".ply",
                                   "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz + "element extra 1\n" + xyz +
                                       "end_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n");
            }),
            "");
}

TEST(MeshPrecheck, MaterialLibrariesAsAssimpNamesThem) {
  EXPECT_EQ(obj_material_libraries("v 0 0 0\nmtllib a.mtl\r\nmtllib\t my file.mtl \t\nmtllib\n# mtllib c.mtl\n"
                                   "  mtllib indented.mtl\nmtllibx x.mtl\n"),
            (std::vector<std::string>{"a.mtl", "my file.mtl \t"}));
  EXPECT_TRUE(obj_material_libraries("").empty());
  // NUL and form feed end lines; a backslash before a line end joins the
  // text after the next newline, also at the end of the file
  EXPECT_EQ(obj_material_libraries(",o \0mtllib \x01\0x\fmtllib f.mtl\nmtl\\\r\nlib j.mtl\nmtllib e\\"s),
            (std::vector<std::string>{"\x01", "f.mtl", "j.mtl", "e"}));
}

// Comments and blank lines may precede the first material; a statement may
// not (Assimp 5.2 wrote `a ...` there through a null material).
TEST(MeshPrecheck, MaterialStatementsNeedAMaterial) {
  EXPECT_EQ(error_of([] { check_mtl_statements("m.mtl", "# exported\n\n  \t\r\nnewmtl red\nKd 1 0 0\na 0.1\n"); }), "");
  EXPECT_EQ(error_of([] { check_mtl_statements("m.mtl", ""); }), "");
  EXPECT_EQ(error_of([] { check_mtl_statements("m.mtl", "\nKd 1 0 0\nnewmtl red\n"); }),
            "m.mtl, line 2: 'Kd' comes before the first newmtl, so it belongs to no material");
  EXPECT_NE(error_of([] { check_mtl_statements("m.mtl", "a 0.1 newmtl x"); }).find("line 1: 'a' comes before"),
            std::string::npos);
  EXPECT_EQ(error_of([] { check_mtl_statements("m.mtl", "\xEF\xBB\xBFnewmtl red\nKd 1 0 0\n"); }), "");
  EXPECT_EQ(error_of([] { check_mtl_statements("m.mtl", "# c\r\n# d\0Kd 1 0 0\nnewmtl red\n"s); }),
            "m.mtl, line 2: 'Kd' comes before the first newmtl, so it belongs to no material");
}

}  // namespace
}  // namespace rtcl::test
