// `rtcl trace` and `rtcl render` on broken files of every kind users meet:
// each run ends within seconds, with exit 1, one "rtcl: error:" line naming
// the file and the problem, no output file, and memory in proportion to the
// file (a 100-byte file declaring 2^31 vertices must not allocate gigabytes).
// The files are generated here, into a temporary directory.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "rtcl/io/ray_file.hpp"
#include "support/cli_run.hpp"
#include "support/temp_dir.hpp"

namespace rtcl::test {
namespace {

// Far above what rtcl needs to reject a small file (tens of MiB, more under
// AddressSanitizer), far below what a declared 2^31 elements would cost.
constexpr double max_rss_mib = 400.0;
constexpr double max_seconds = 10.0;

template <class T>
void append(std::string& bytes, T value) {
  bytes.append(reinterpret_cast<const char*>(&value), sizeof value);
}

const char* const tetra_vertices = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";

std::string ply_header(const std::string& format, std::uint64_t vertices, std::uint64_t faces,
                       const std::string& list = "list uchar int") {
  return "ply\nformat " + format + " 1.0\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face " + std::to_string(faces) +
         "\nproperty " + list + " vertex_indices\nend_header\n";
}

// A binary little-endian PLY tetrahedron: 4 vertices, 4 triangles.
std::string binary_ply(float first_x = 0.0f) {
  std::string bytes = ply_header("binary_little_endian", 4, 4);
  const float xyz[4][3] = {{first_x, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const auto& v : xyz)
    for (float c : v) append(bytes, c);
  const int faces[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
  for (const auto& f : faces) {
    append(bytes, std::uint8_t{3});
    for (int i : f) append(bytes, i);
  }
  return bytes;
}

// A binary STL with `count` triangles declared and `present` written.
std::string binary_stl(std::uint32_t count, std::uint32_t present, float first_x = 0.0f) {
  std::string bytes(80, ' ');
  append(bytes, count);
  for (std::uint32_t t = 0; t < present; ++t) {
    const float record[12] = {0, 0, 1, first_x, 0, 0, 1, 0, 0, 0, 1, 0};
    for (float f : record) append(bytes, f);
    append(bytes, std::uint16_t{0});
  }
  return bytes;
}

struct Broken {
  std::string file;      // as named on the command line
  std::string problem;   // a fragment of the expected message
};

class MalformedFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    std::vector<Ray> rays = {{0.2f, 0.2f, -1.0f, 0.0f, 0.0f, 1.0f, 0.0f, std::numeric_limits<float>::infinity()}};
    write_rays(dir.file("in.rays"), rays);
  }

  // One broken input: exit 1, one error line naming the file and the problem,
  // no output, quick, small.
  void expect_rejected(const std::vector<std::string>& args, const Broken& b, const std::string& output) {
    SCOPED_TRACE(b.file);
    CliRun run = run_cli(dir, args);
    expect_failure(run, b.file + ": ", dir, output);
    EXPECT_NE(run.err.find(b.problem), std::string::npos) << "expected '" << b.problem << "' in: " << run.err;
    EXPECT_LT(run.seconds, max_seconds) << run.err;
    EXPECT_LT(run.max_rss_mib, max_rss_mib) << run.err;
  }

  void expect_trace_rejects(const Broken& b) {
    expect_rejected({"trace", b.file, "in.rays", "-o", "out.hits"}, b, "out.hits");
  }

  TempDir dir;
};

TEST_F(MalformedFiles, TruncatedBinaryFiles) {
  std::string ply = binary_ply();
  dir.write("truncated.ply", ply.substr(0, ply.size() - 20));
  expect_trace_rejects({"truncated.ply", "PLY element 'face' 2 of 4"});
  dir.write("header_only.ply", ply_header("binary_little_endian", 4, 4));
  expect_trace_rejects({"header_only.ply", "declares 4 'vertex' elements"});
  dir.write("truncated.stl", binary_stl(2, 1));
  expect_trace_rejects({"truncated.stl", "binary STL header declares 2 triangles, which take 184 bytes, but the "
                                         "file has 134 bytes"});
}

TEST_F(MalformedFiles, HugeDeclaredCountsWithLittleData) {
  std::string ply = ply_header("binary_little_endian", std::uint64_t(1) << 31, 1);
  ply.append(100, '\0');
  dir.write("huge.ply", ply);
  expect_trace_rejects({"huge.ply", "declares 2147483648 'vertex' elements"});
  dir.write("huge_ascii.ply", ply_header("ascii", std::uint64_t(1) << 31, 1) + "0 0 0\n");
  expect_trace_rejects({"huge_ascii.ply", "declares 2147483648 'vertex' elements"});
  // One face whose list declares 4e9 indices.
  std::string list = ply_header("binary_little_endian", 3, 1, "list uint int");
  for (int i = 0; i < 9; ++i) append(list, 0.0f);
  append(list, std::uint32_t{4000000000u});
  append(list, 0);
  dir.write("huge_list.ply", list);
  expect_trace_rejects({"huge_list.ply", "a list declares 4000000000 entries"});
  dir.write("huge_ascii_list.ply", ply_header("ascii", 3, 1, "list uint int") + "0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n");
  expect_trace_rejects({"huge_ascii_list.ply", "a list declares 4000000000 entries"});
  dir.write("huge.stl", binary_stl(0x7fffffffu, 1));
  expect_trace_rejects({"huge.stl", "binary STL header declares 2147483647 triangles"});
}

TEST_F(MalformedFiles, OutOfRangeAndNegativeIndices) {
  dir.write("range.obj", std::string(tetra_vertices) + "f 1 2 9\n");
  expect_trace_rejects({"range.obj", "vertex index out of range"});
  dir.write("negative.obj", std::string(tetra_vertices) + "f -1 -2 -9\n");
  expect_trace_rejects({"negative.obj", "index"});
  std::string ascii = ply_header("ascii", 3, 1) + "0 0 0\n1 0 0\n0 1 0\n";
  dir.write("range.ply", ascii + "3 0 1 99\n");
  expect_trace_rejects({"range.ply", "vertex index"});
  dir.write("negative.ply", ascii + "3 0 1 -5\n");
  expect_trace_rejects({"negative.ply", "vertex index"});
  dir.write("negative_count.ply", ply_header("binary_little_endian", 3, 1, "list char int") +
                                      std::string(36, '\0') + std::string(1, '\xff') + std::string(12, '\0'));
  expect_trace_rejects({"negative_count.ply", "a negative number of entries"});
}

TEST_F(MalformedFiles, NonFiniteCoordinates) {
  dir.write("nan.obj", "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n");
  expect_trace_rejects({"nan.obj", "NaN or infinite vertex coordinate"});
  dir.write("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n");
  expect_trace_rejects({"inf.obj", "NaN or infinite vertex coordinate"});
  dir.write("nan.ply", binary_ply(std::numeric_limits<float>::quiet_NaN()));
  expect_trace_rejects({"nan.ply", "NaN or infinite vertex coordinate"});
  dir.write("inf.stl", binary_stl(1, 1, std::numeric_limits<float>::infinity()));
  expect_trace_rejects({"inf.stl", "NaN or infinite vertex coordinate"});
}

TEST_F(MalformedFiles, EmptyFilesDirectoriesAndGarbage) {
  for (const char* name : {"empty.obj", "empty.ply", "empty.stl"}) {
    dir.write(name, "");
    expect_trace_rejects({name, "the file is empty"});
  }
  std::filesystem::create_directory(dir.file("folder.obj"));
  expect_trace_rejects({"folder.obj", "is a directory"});
  std::mt19937 random(7);
  std::string garbage(4096, '\0');
  for (char& c : garbage) c = static_cast<char>(random());
  dir.write("garbage.obj", garbage);
  expect_trace_rejects({"garbage.obj", "garbage.obj: "});
  dir.write("garbage.ply", "ply\n" + garbage);
  expect_trace_rejects({"garbage.ply", "PLY header line 2"});
  dir.write("garbage.stl", garbage);
  expect_trace_rejects({"garbage.stl", "binary STL header declares"});
}

// An OBJ whose MTL names itself, and an OBJ that names itself as its MTL:
// both end quickly, refused (their first statement, mtllib, comes before
// any material).
TEST_F(MalformedFiles, SelfReferencingMaterialFiles) {
  dir.write("loop.mtl", "mtllib loop.mtl\nnewmtl a\nKd 1 0 0\nmap_Kd loop.mtl\n");
  dir.write("loop.obj", "mtllib loop.mtl\nusemtl a\nf 1 2 3\n");
  expect_trace_rejects({"loop.obj", "loop.obj: "});
  dir.write("itself.obj", "mtllib itself.obj\nusemtl itself\nf 1 2 3\n");
  expect_trace_rejects({"itself.obj", "itself.obj: "});
}

// A material statement before the MTL file's first newmtl (a fuzzer's
// input on which Assimp 5.2 crashed) is refused before Assimp reads it.
TEST_F(MalformedFiles, MaterialStatementBeforeTheFirstMaterial) {
  dir.write("early.mtl", "a 0.1 newmtl glass\n");
  dir.write("early.obj", "mtllib early.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl glass\nf 1 2 3\n");
  expect_trace_rejects({"early.obj", "early.mtl, line 1: 'a' comes before the first newmtl"});
  // A material file that is not there: Assimp reads the OBJ's name with .mtl.
  dir.write("fallback.mtl", "\nKd 1 0 0\nnewmtl glass\n");
  dir.write("fallback.obj", "mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl glass\nf 1 2 3\n");
  expect_trace_rejects({"fallback.obj", "fallback.mtl, line 2: 'Kd' comes before the first newmtl"});
}

TEST_F(MalformedFiles, SceneFileWhoseMeshIsADirectory) {
  std::filesystem::create_directory(dir.file("meshes.obj"));
  dir.write("scene.json", R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
                               "objects": [{"type": "mesh", "file": "meshes.obj"}]})");
  expect_rejected({"render", "scene.json", "-o", "out.png"}, {"scene.json", "objects[0].file"}, "out.png");
  CliRun run = run_cli(dir, {"render", "scene.json", "-o", "out.png"});
  EXPECT_NE(run.err.find("is a directory"), std::string::npos) << run.err;
  std::filesystem::create_directory(dir.file("scene_dir.json"));
  expect_rejected({"render", "scene_dir.json", "-o", "out.png"}, {"scene_dir.json", "is a directory"}, "out.png");
}

}  // namespace
}  // namespace rtcl::test
