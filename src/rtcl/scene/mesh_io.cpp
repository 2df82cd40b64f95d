// Mesh import through Assimp 5.2 with no post-processing steps: polygons are
// read as the file states them and fan-triangulated here, so that primitive
// ids follow the file's face order (see mesh_io.hpp).
#include "rtcl/scene/mesh_io.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string_view>
#include <unordered_map>
#include <unordered_set>

#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/scene.h>

#include "rtcl/error.hpp"
#include "rtcl/scene/mesh_precheck.hpp"

namespace rtcl {

namespace fs = std::filesystem;

namespace {

const char* const supported_extensions[] = {".obj", ".ply", ".stl"};

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

void check_input_file(const std::string& path) {
  std::error_code ec;
  fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw Error(path + ": no such mesh file");
  if (fs::is_directory(status)) throw Error(path + ": is a directory, not a mesh file");
  std::string ext = lower_extension(path);
  if (std::find(std::begin(supported_extensions), std::end(supported_extensions), ext) ==
      std::end(supported_extensions))
    throw Error(path + ": unsupported mesh format '" + (ext.empty() ? std::string("(no extension)") : ext) +
                "' (rtcl reads .obj with .mtl, .ply and .stl)");
  std::ifstream probe(path, std::ios::binary);
  if (!probe) throw Error(path + ": cannot read: " + std::strerror(errno));
}

// The whole file, or its first `limit` bytes.
std::string read_file(const std::string& path, std::size_t limit = std::numeric_limits<std::size_t>::max()) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  std::size_t size = static_cast<std::size_t>(std::max<std::streamoff>(in.tellg(), 0));
  std::string text(std::min(size, limit), '\0');
  in.seekg(0);
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  return text;
}

// OBJ declares no sizes: only its first byte is read (is it empty?).
void check_sizes(const std::string& path) {
  std::string ext = lower_extension(path);
  check_declared_sizes(path, ext, ext == ".obj" ? read_file(path, 1) : read_file(path));
}

glm::vec3 color(const aiMaterial& m, const char* key, unsigned type, unsigned index, glm::vec3 fallback) {
  aiColor3D c;
  if (m.Get(key, type, index, c) != AI_SUCCESS) return fallback;
  return {c.r, c.g, c.b};
}

float scalar(const aiMaterial& m, const char* key, unsigned type, unsigned index, float fallback) {
  ai_real v = 0;
  if (m.Get(key, type, index, v) != AI_SUCCESS) return fallback;
  return static_cast<float>(v);
}

MeshMaterial convert(const aiMaterial& m) {
  MeshMaterial out;
  aiString name;
  if (m.Get(AI_MATKEY_NAME, name) == AI_SUCCESS) out.name = name.C_Str();
  out.ambient = color(m, AI_MATKEY_COLOR_AMBIENT, out.ambient);
  out.diffuse = color(m, AI_MATKEY_COLOR_DIFFUSE, out.diffuse);
  out.specular = color(m, AI_MATKEY_COLOR_SPECULAR, out.specular);
  out.emission = color(m, AI_MATKEY_COLOR_EMISSIVE, out.emission);
  out.shininess = scalar(m, AI_MATKEY_SHININESS, out.shininess);
  out.ior = scalar(m, AI_MATKEY_REFRACTI, out.ior);
  out.opacity = scalar(m, AI_MATKEY_OPACITY, out.opacity);
  return out;
}

// Exact-position vertex sharing: equal coordinates (+0 and -0 alike) become
// one vertex, so the mesh is indexed as in the file even where Assimp
// duplicates a vertex per face corner (OBJ, STL).
struct VertexKey {
  std::array<std::uint32_t, 3> bits;
  bool operator==(const VertexKey&) const = default;
};
struct VertexKeyHash {
  std::size_t operator()(const VertexKey& k) const {
    std::uint64_t h = 1469598103934665603ull;
    for (std::uint32_t b : k.bits) h = (h ^ b) * 1099511628211ull;
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};

class MeshBuilder {
 public:
  MeshBuilder(const aiScene& scene, std::string path) : scene_(scene), path_(std::move(path)) {
    out_.geometry.source = path_;
  }

  // Appends one mesh instance placed by `transform`, as one object.
  void add(const aiMesh& mesh, const aiMatrix4x4& transform, bool identity, const std::string& node_name) {
    std::uint32_t material = mesh.mMaterialIndex;
    if (material >= std::max(scene_.mNumMaterials, 1u))
      throw Error(path_ + ": mesh '" + node_name + "' refers to material " + std::to_string(material) + " of " +
                  std::to_string(scene_.mNumMaterials));
    MeshObject object;
    object.name = node_name.empty() ? std::string(mesh.mName.C_Str()) : node_name;
    object.first_triangle = out_.geometry.triangles.size();
    object.material = material;
    remap_.assign(mesh.mNumVertices, unmapped);
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices < 3) continue;  // points and lines
      for (unsigned k = 0; k < face.mNumIndices; ++k)
        if (face.mIndices[k] >= mesh.mNumVertices)
          throw Error(path_ + ": face " + std::to_string(f) + " of object '" + object.name + "' uses vertex index " +
                      std::to_string(face.mIndices[k]) + ", but the object has only " +
                      std::to_string(mesh.mNumVertices) + " vertices");
      // Fan (v0, vk, vk+1): polygons are assumed convex and planar.
      std::uint32_t v0 = vertex(mesh, face.mIndices[0], transform, identity, object.name);
      for (unsigned k = 1; k + 1 < face.mNumIndices; ++k) {
        std::uint32_t a = vertex(mesh, face.mIndices[k], transform, identity, object.name);
        std::uint32_t b = vertex(mesh, face.mIndices[k + 1], transform, identity, object.name);
        out_.geometry.triangles.push_back({v0, a, b});
        out_.triangle_material.push_back(material);
      }
    }
    object.triangle_count = out_.geometry.triangles.size() - object.first_triangle;
    if (object.triangle_count > 0) out_.objects.push_back(std::move(object));
  }

  LoadedMesh finish() {
    for (unsigned i = 0; i < scene_.mNumMaterials; ++i) out_.materials.push_back(convert(*scene_.mMaterials[i]));
    if (out_.materials.empty()) out_.materials.push_back(MeshMaterial{"default"});
    return std::move(out_);
  }

 private:
  static constexpr std::uint32_t unmapped = std::numeric_limits<std::uint32_t>::max();

  std::uint32_t vertex(const aiMesh& mesh, unsigned index, const aiMatrix4x4& transform, bool identity,
                       const std::string& object) {
    std::uint32_t& mapped = remap_[index];
    if (mapped != unmapped) return mapped;
    aiVector3D p = identity ? mesh.mVertices[index] : transform * mesh.mVertices[index];
    glm::vec3 v(static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z));
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) {
      char xyz[96];
      std::snprintf(xyz, sizeof xyz, "(%g, %g, %g)", v.x, v.y, v.z);
      throw Error(path_ + ": triangle " + std::to_string(out_.geometry.triangles.size()) + " (object '" + object +
                  "') has a NaN or infinite vertex coordinate " + xyz);
    }
    v += glm::vec3(0.0f);  // -0 becomes +0
    VertexKey key;
    std::memcpy(key.bits.data(), &v, sizeof v);
    auto [it, inserted] = shared_.try_emplace(key, static_cast<std::uint32_t>(out_.geometry.vertices.size()));
    if (inserted) {
      if (out_.geometry.vertices.size() >= unmapped) throw Error(path_ + ": more than 2^32-1 vertices");
      out_.geometry.vertices.push_back(v);
    }
    mapped = it->second;
    return mapped;
  }

  const aiScene& scene_;
  std::string path_;
  LoadedMesh out_;
  std::vector<std::uint32_t> remap_;  // mesh vertex -> geometry vertex, per mesh
  std::unordered_map<VertexKey, std::uint32_t, VertexKeyHash> shared_;
};

// Notes on the two places where Assimp 5.2's OBJ importer departs from the
// file (see mesh_io.hpp), found by a scan of the statement keywords.
std::vector<std::string> obj_notes(const std::string& path, const std::string& text) {
  std::vector<std::string> notes;
  std::unordered_set<std::string> names;  // o and g names seen so far
  std::string current_object, repeated;
  std::size_t line_number = 0, repeated_line = 0, faces_before_usemtl = 0;
  bool mtllib = false, usemtl = false;
  for (std::size_t pos = 0; pos < text.size();) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    ++line_number;
    std::size_t a = text.find_first_not_of(" \t", pos);
    if (a < end) {
      std::size_t b = std::min(text.find_first_of(" \t\r", a), end);
      std::string_view keyword(text.data() + a, b - a);
      if (keyword == "f") {
        if (mtllib && !usemtl) ++faces_before_usemtl;
      } else if (keyword == "mtllib") {
        mtllib = true;
      } else if (keyword == "usemtl") {
        usemtl = true;
      } else if (keyword == "o" || keyword == "g") {
        std::size_t c = std::min(text.find_first_not_of(" \t", b), end), e = end;
        while (e > c && (text[e - 1] == '\r' || text[e - 1] == ' ' || text[e - 1] == '\t')) --e;
        std::string name = text.substr(c, e - c);
        bool seen = names.count(name) > 0;
        if (keyword == "o" && seen && name != current_object && repeated.empty()) {
          repeated = name;
          repeated_line = line_number;
        }
        if (!seen) names.insert(name);
        current_object = name;
      }
    }
    pos = end + 1;
  }
  if (!repeated.empty())
    notes.push_back(path + ": line " + std::to_string(repeated_line) + " reuses the object name '" + repeated +
                    "'; Assimp then files faces under the earlier object, so triangle ids may not follow the "
                    "file's face order");
  if (faces_before_usemtl > 0)
    notes.push_back(path + ": " + std::to_string(faces_before_usemtl) +
                    (faces_before_usemtl == 1 ? " face comes" : " faces come") +
                    " before the first usemtl; Assimp gives them the last material of the MTL file");
  return notes;
}

// The material files of an OBJ (`text`) as Assimp 5.2 finds them, checked
// before Assimp reads them (mesh_precheck.hpp): each mtllib name appended to
// the OBJ's directory as written in `path`, or where there is no such file,
// the OBJ's own name with "mtl" for its last three characters (Assimp's
// fallback); neither: Assimp reports it and reads no material.
void check_material_files(const std::string& path, std::string_view text) {
  const std::string directory = path.substr(0, path.rfind('/') + 1);  // "" when path has no '/' (npos + 1)
  for (const std::string& name : obj_material_libraries(text)) {
    std::error_code ec;
    std::string mtl = directory + name;
    if (!fs::is_regular_file(mtl, ec)) mtl = path.substr(0, path.size() - 3) + "mtl";
    if (fs::is_regular_file(mtl, ec)) check_mtl_statements(path + ": material file " + mtl, read_file(mtl));
  }
}

}  // namespace

LoadedMesh load_mesh(const std::string& path) {
  check_input_file(path);
  check_sizes(path);
  const bool obj = lower_extension(path) == ".obj";
  const std::string obj_text = obj ? read_file(path) : std::string();
  if (obj) check_material_files(path, obj_text);
  Assimp::Importer importer;
  const aiScene* scene = nullptr;
  try {
    // No post-processing: aiProcess_Triangulate would not keep the fan order,
    // and sorting or joining steps would reorder faces.
    scene = importer.ReadFile(path, 0);
  } catch (const std::exception& e) {
    throw Error(path + ": cannot import mesh: " + e.what());
  }
  if (!scene) throw Error(path + ": cannot import mesh: " + std::string(importer.GetErrorString()));

  MeshBuilder builder(*scene, path);
  std::size_t faces = 0;
  // Depth-first over the node tree: a node's meshes in its order, then its
  // children in order.
  struct Pending {
    const aiNode* node;
    aiMatrix4x4 transform;
  };
  std::vector<Pending> stack;
  if (scene->mRootNode) stack.push_back({scene->mRootNode, scene->mRootNode->mTransformation});
  while (!stack.empty()) {
    Pending top = stack.back();
    stack.pop_back();
    const aiNode& node = *top.node;
    bool identity = top.transform.IsIdentity();
    for (unsigned i = 0; i < node.mNumMeshes; ++i) {
      unsigned id = node.mMeshes[i];
      if (id >= scene->mNumMeshes)
        throw Error(path + ": node '" + std::string(node.mName.C_Str()) + "' refers to mesh " + std::to_string(id) +
                    " of " + std::to_string(scene->mNumMeshes));
      faces += scene->mMeshes[id]->mNumFaces;
      builder.add(*scene->mMeshes[id], top.transform, identity, node.mName.C_Str());
    }
    for (unsigned i = node.mNumChildren; i-- > 0;)
      stack.push_back({node.mChildren[i], top.transform * node.mChildren[i]->mTransformation});
  }
  LoadedMesh mesh = builder.finish();
  if (obj) mesh.notes = obj_notes(path, obj_text);
  if (mesh.geometry.triangles.empty())
    throw Error(path + ": no triangles (" + std::to_string(faces) + " faces, none with three or more vertices)");
  return mesh;
}

}  // namespace rtcl
