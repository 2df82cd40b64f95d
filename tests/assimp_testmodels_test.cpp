// Every OBJ, PLY and STL file of Debian's assimp-testmodels package against
// Assimp's own import of it: rtcl's mesh loader (its size pre-checks
// included) reads each file Assimp reads, with one triangle per fan triangle
// of Assimp's faces, and refuses a file only where Assimp agrees: Assimp's
// import fails, or it finds no face of three or more vertices.
#include <assimp/Importer.hpp>
#include <assimp/scene.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "rtcl/error.hpp"
#include "rtcl/scene/mesh_io.hpp"

namespace rtcl::test {
namespace {

namespace fs = std::filesystem;

// Where Debian's assimp-testmodels installs its models.
constexpr const char* kModels = "/usr/share/assimp/models";

std::vector<std::string> mesh_files() {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& entry : fs::recursive_directory_iterator(kModels, ec)) {
    if (!entry.is_regular_file()) continue;
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (ext == ".obj" || ext == ".ply" || ext == ".stl") out.push_back(entry.path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// Triangles of Assimp's own import (no post-processing, as load_mesh): each
// face of n >= 3 vertices is n - 2 fan triangles, per node that places its
// mesh. -1: the import failed.
long assimp_triangles(const std::string& path, std::string* error) {
  Assimp::Importer importer;
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFile(path, 0);
  } catch (const std::exception& e) {
    *error = e.what();
    return -1;
  }
  if (!scene) {
    *error = importer.GetErrorString();
    return -1;
  }
  long triangles = 0;
  std::vector<const aiNode*> stack;
  if (scene->mRootNode) stack.push_back(scene->mRootNode);
  while (!stack.empty()) {
    const aiNode* node = stack.back();
    stack.pop_back();
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
      if (node->mMeshes[i] >= scene->mNumMeshes) continue;
      const aiMesh& mesh = *scene->mMeshes[node->mMeshes[i]];
      for (unsigned f = 0; f < mesh.mNumFaces; ++f)
        if (mesh.mFaces[f].mNumIndices >= 3) triangles += mesh.mFaces[f].mNumIndices - 2;
    }
    for (unsigned i = 0; i < node->mNumChildren; ++i) stack.push_back(node->mChildren[i]);
  }
  return triangles;
}

TEST(AssimpTestModels, EachLoadsOrAssimpAgreesItHasNoTriangles) {
  std::vector<std::string> files = mesh_files();
  if (files.empty())
    GTEST_SKIP() << "no OBJ, PLY or STL file under " << kModels
                 << ": install Debian's assimp-testmodels (scripts/setup.sh does)";
  int loaded = 0, refused = 0;
  for (const std::string& path : files) {
    SCOPED_TRACE(path);
    std::string assimp_error;
    long expected = assimp_triangles(path, &assimp_error);
    std::string rtcl_error;
    std::size_t triangles = 0;
    try {
      triangles = load_mesh(path).geometry.triangles.size();
    } catch (const Error& e) {
      rtcl_error = e.what();
    }
    if (rtcl_error.empty()) {
      ++loaded;
      EXPECT_EQ(static_cast<long>(triangles), expected) << "rtcl's triangles against Assimp's fan triangles";
    } else {
      ++refused;
      EXPECT_LE(expected, 0) << "rtcl refuses a file Assimp reads (" << expected << " triangles): " << rtcl_error;
      EXPECT_EQ(rtcl_error.rfind(path, 0), 0u) << "the error names the file: " << rtcl_error;
    }
  }
  std::printf("[ measure  ] %zu files of assimp-testmodels: %d load, %d refused (Assimp finds no triangles)\n",
              files.size(), loaded, refused);
  EXPECT_GT(loaded, 0);
}

}  // namespace
}  // namespace rtcl::test
