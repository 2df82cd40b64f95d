// Size checks of mesh files before Assimp reads them. Assimp allocates what a
// file header declares (PLY element counts and list lengths, the triangle
// count of a binary STL) before it reads the data, so a 100-byte file that
// declares 2^31 vertices would cost gigabytes. These checks hold every
// declared count against the bytes that are actually there.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace rtcl {

// Throws Error naming `path`, the declared size and the available bytes when
// `bytes` (the whole file) cannot hold what it declares:
// - any file: empty;
// - PLY (ASCII or binary): a header without end_header (Assimp 5.2 can loop
//   forever on one), a malformed format, element or property line, a
//   property after a line that ended its element's property list (Assimp
//   would ignore it), an element count, or a list length of any element
//   instance, that needs more bytes than remain (truncated data included);
//   lines with unknown keywords are skipped, as Assimp skips them;
// - binary STL (a file not starting with "solid"): a size other than the
//   84 + 50 * triangle_count bytes its header declares.
// `extension` is lower case with its dot (".ply").
void check_declared_sizes(const std::string& path, const std::string& extension, std::string_view bytes);

// The material files an OBJ names (`text`: the whole OBJ), as Assimp 5.2
// reads them: a line ends at any of '\n', '\r', '\0' and '\f', a '\\' before
// a line end continues the line after the next '\n', and a line that starts
// with the word mtllib names the rest of the line after its blanks, trailing
// blanks included (a bare mtllib names none).
std::vector<std::string> obj_material_libraries(std::string_view text);

// Throws Error naming `what` and the line when an MTL file (`bytes`: the
// whole file, lines ended as above) has a statement other than a comment
// before its first newmtl: it belongs to no material, and Assimp 5.2 writes
// some such statements through a null material (`a 0.1 newmtl x` and, after
// a NUL, `4` crashed it; found by fuzzing).
void check_mtl_statements(const std::string& what, std::string_view bytes);

}  // namespace rtcl
