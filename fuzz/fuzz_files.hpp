// Fuzz inputs reach the loaders the way users' files do: as files on disk.
// Each process writes them into its own scratch directory (removed at exit),
// so parallel fuzzing jobs never share a file.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace rtcl::fuzz {

// The process's scratch directory, created on first use. It also holds
// fixtures scene files may name: "mesh.obj" (a valid tetrahedron) and
// "folder.obj" (a directory).
const std::string& scratch_dir();

// Writes bytes to scratch_dir()/name and returns that path.
std::string write_scratch(const std::string& name, std::string_view bytes);

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace rtcl::fuzz
