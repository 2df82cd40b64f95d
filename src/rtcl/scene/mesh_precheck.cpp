#include "rtcl/scene/mesh_precheck.hpp"

#include <charconv>
#include <cstdint>
#include <algorithm>
#include <optional>
#include <vector>

#include "rtcl/error.hpp"

namespace rtcl {

namespace {

// A PLY header as far as sizes go (http://paulbourke.net/dataformats/ply/).
struct PlyProperty {
  std::size_t scalar_bytes = 0;  // the value, or for a list each entry
  std::size_t count_bytes = 0;   // list length field; 0 for a scalar
  bool count_signed = false;     // the length field's type is signed (char, short, int)
};
struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};
enum class PlyFormat { ascii, binary_little_endian, binary_big_endian };
struct PlyHeader {
  PlyFormat format = PlyFormat::ascii;
  std::vector<PlyElement> elements;
  std::size_t body_offset = 0;  // first byte after "end_header\n"
};

bool ply_type_signed(std::string_view type) {
  for (const char* t : {"char", "short", "int", "int8", "int16", "int32"})
    if (type == t) return true;
  return false;
}

std::size_t ply_type_bytes(std::string_view type) {
  for (const char* t : {"char", "uchar", "int8", "uint8"})
    if (type == t) return 1;
  for (const char* t : {"short", "ushort", "int16", "uint16"})
    if (type == t) return 2;
  for (const char* t : {"int", "uint", "int32", "uint32", "float", "float32"})
    if (type == t) return 4;
  for (const char* t : {"double", "float64"})
    if (type == t) return 8;
  return 0;
}

bool assimp_line_end(char c) { return c == '\n' || c == '\r' || c == '\0' || c == '\f'; }

// Calls `visit(line, line_number)` for each line of `text` as Assimp 5.2's
// OBJ and MTL parsers split it (its IsLineEnd): a line ends at any of '\n',
// '\r', '\0' and '\f'. With `continuations` (the OBJ reader's
// IOStreamBuffer::getNextDataLine), a '\\' just before a line end or the
// end of the file is dropped with everything through the next '\n', and the
// line goes on after it. `line_number` counts '\n' as an editor does. Stops
// when `visit` returns false.
template <class Visit>
void for_each_assimp_line(std::string_view text, bool continuations, Visit&& visit) {
  std::string joined;
  std::size_t line_number = 1, start_line = 1;
  for (std::size_t pos = 0; pos < text.size();) {
    std::size_t end = pos;
    while (end < text.size() && !assimp_line_end(text[end])) ++end;
    std::string_view line = text.substr(pos, end - pos);
    if (continuations && !line.empty() && line.back() == '\\') {
      joined.append(line.substr(0, line.size() - 1));
      std::size_t newline = text.find('\n', end);
      if (newline == std::string_view::npos) break;
      ++line_number;
      pos = newline + 1;
      continue;
    }
    if (!joined.empty()) line = joined.append(line);
    if (!visit(line, start_line)) return;
    joined.clear();
    if (end < text.size() && text[end] == '\n') ++line_number;
    start_line = line_number;
    pos = end + 1;
  }
  if (!joined.empty()) visit(std::string_view(joined), start_line);
}

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

std::optional<std::uint64_t> unsigned_number(std::string_view text) {
  std::uint64_t value = 0;
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

// The header as Assimp 5.2's PLY parser reads it (PLY::DOM::ParseHeader),
// checked where it matters: a line with an unknown keyword (Blender writes
// "Created by Blender3D ..." without "comment") is skipped, and so are
// comment and obj_info lines; the format, element and property lines are
// checked strictly, since their sizes bound what Assimp allocates; the file
// must reach end_header (Assimp 5.2 can loop forever past the end). Assimp
// ends an element's property list at the first line that is not a property
// and ignores property lines after it: such a file is refused, since Assimp
// would read its data with properties missing. An element name declared
// twice is refused too: Assimp sizes its arrays for an element (say
// 'vertex') by the first declaration's count and then writes the second's
// instances past their end.
PlyHeader parse_ply_header(const std::string& path, std::string_view bytes) {
  PlyHeader header;
  bool format_seen = false;
  bool properties_open = false;  // the last non-blank line was an element or one of its properties
  std::size_t pos = 0;
  for (int line_number = 1;; ++line_number) {
    auto bad = [&](const std::string& what) {
      throw Error(path + ": PLY header line " + std::to_string(line_number) + ": " + what);
    };
    std::size_t end = bytes.find('\n', pos);
    if (end == std::string_view::npos) bad("the file ends before 'end_header'");
    std::vector<std::string_view> w = words(bytes.substr(pos, end - pos));
    pos = end + 1;
    if (line_number == 1) {
      if (w.size() != 1 || w[0] != "ply") bad("not a PLY file (the first line is not 'ply')");
      continue;
    }
    if (w.empty()) continue;
    if (w[0] == "end_header") {
      if (!format_seen) bad("'end_header' before any 'format' line");
      header.body_offset = pos;
      return header;
    }
    if (w[0] == "format") {
      if (w.size() != 3 || format_seen) bad("expected one 'format ascii|binary_little_endian|binary_big_endian 1.0'");
      format_seen = true;
      properties_open = false;
      if (w[1] == "ascii") header.format = PlyFormat::ascii;
      else if (w[1] == "binary_little_endian") header.format = PlyFormat::binary_little_endian;
      else if (w[1] == "binary_big_endian") header.format = PlyFormat::binary_big_endian;
      else bad("unknown format '" + std::string(w[1]) + "'");
    } else if (w[0] == "element") {
      std::optional<std::uint64_t> count = w.size() == 3 ? unsigned_number(w[2]) : std::nullopt;
      if (!count) bad("expected 'element NAME COUNT' with a non-negative integer COUNT");
      for (const PlyElement& e : header.elements)
        if (e.name == w[1])
          bad("element '" + e.name + "' is declared a second time (Assimp would write its instances past the " +
              "arrays sized for the first)");
      header.elements.push_back({std::string(w[1]), *count, {}});
      properties_open = true;
    } else if (w[0] == "property") {
      if (header.elements.empty()) continue;  // Assimp skips it as an unknown line: it belongs to no element
      if (!properties_open)
        bad("a property of element '" + header.elements.back().name + "' after a line that is not a property " +
            "(Assimp ends the element's properties there and would ignore this one)");
      PlyProperty p;
      if (w.size() == 5 && w[1] == "list") {
        p.count_bytes = ply_type_bytes(w[2]);
        p.count_signed = ply_type_signed(w[2]);
        p.scalar_bytes = ply_type_bytes(w[3]);
        if (p.count_bytes == 0 || p.scalar_bytes == 0) bad("unknown type in a list property");
      } else if (w.size() == 3) {
        p.scalar_bytes = ply_type_bytes(w[1]);
        if (p.scalar_bytes == 0) bad("unknown property type '" + std::string(w[1]) + "'");
      } else {
        bad("expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'");
      }
      header.elements.back().properties.push_back(p);
    } else {
      properties_open = false;  // comment, obj_info or an unknown keyword: skipped, as Assimp does
    }
  }
}

[[noreturn]] void too_short(const std::string& path, const PlyElement& element, std::uint64_t instance,
                            const std::string& what) {
  throw Error(path + ": PLY element '" + element.name + "' " + std::to_string(instance) + " of " +
              std::to_string(element.count) + ": " + what + " (truncated file, or a header that declares more " +
              "than the file holds)");
}

// The fewest bytes one instance can take: binary, every fixed field and every
// list length field; ASCII, one digit and one separator per value.
std::uint64_t min_instance_bytes(const PlyElement& element, PlyFormat format) {
  std::uint64_t bytes = 0;
  for (const PlyProperty& p : element.properties)
    bytes += format == PlyFormat::ascii ? 2 : (p.count_bytes ? p.count_bytes : p.scalar_bytes);
  return bytes > 0 ? bytes : 1;  // Assimp keeps a record even for an element with no properties
}

// Every element count against the body size, before any instance is read.
// (ASCII: the last value of the file needs no separator, hence one byte more.)
void check_element_counts(const std::string& path, const PlyHeader& header, std::uint64_t body_bytes) {
  std::uint64_t needed = 0;
  std::uint64_t available = body_bytes + (header.format == PlyFormat::ascii ? 1 : 0);
  for (const PlyElement& e : header.elements) {
    std::uint64_t per = min_instance_bytes(e, header.format);
    if (e.count > (available - std::min(needed, available)) / per)
      throw Error(path + ": PLY header declares " + std::to_string(e.count) + " '" + e.name + "' elements of at " +
                  "least " + std::to_string(per) + " bytes each, but only " + std::to_string(body_bytes) +
                  " bytes of data follow the header");
    needed += e.count * per;
  }
}

// A list length field as Assimp reads it: negative values of signed types
// become huge unsigned counts, so they are reported as negative here.
std::int64_t read_length(const char* p, const PlyProperty& property, bool big_endian) {
  std::uint64_t value = 0;
  for (std::size_t i = 0; i < property.count_bytes; ++i)
    value = (value << 8) | static_cast<std::uint8_t>(p[big_endian ? i : property.count_bytes - 1 - i]);
  std::size_t bits = 8 * property.count_bytes;
  if (property.count_signed && bits < 64 && (value >> (bits - 1)) != 0) return -1;
  return static_cast<std::int64_t>(value);
}

void walk_binary_body(const std::string& path, const PlyHeader& header, std::string_view body) {
  bool big = header.format == PlyFormat::binary_big_endian;
  std::size_t pos = 0;
  for (const PlyElement& e : header.elements) {
    for (std::uint64_t i = 0; i < e.count; ++i) {
      for (const PlyProperty& p : e.properties) {
        if (p.count_bytes == 0) {
          if (body.size() - pos < p.scalar_bytes) too_short(path, e, i, "the data ends inside it");
          pos += p.scalar_bytes;
          continue;
        }
        if (body.size() - pos < p.count_bytes) too_short(path, e, i, "the data ends inside it");
        std::int64_t length = read_length(body.data() + pos, p, big);
        pos += p.count_bytes;
        if (length < 0) too_short(path, e, i, "a list declares a negative number of entries");
        if (static_cast<std::uint64_t>(length) > (body.size() - pos) / p.scalar_bytes)
          too_short(path, e, i,
                    "a list declares " + std::to_string(length) + " entries of " + std::to_string(p.scalar_bytes) +
                        " bytes, but only " + std::to_string(body.size() - pos) + " bytes remain");
        pos += static_cast<std::size_t>(length) * p.scalar_bytes;
      }
    }
  }
}

void walk_ascii_body(const std::string& path, const PlyHeader& header, std::string_view body) {
  std::size_t pos = 0;
  auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  auto next_token = [&]() -> std::optional<std::string_view> {
    while (pos < body.size() && space(body[pos])) ++pos;
    std::size_t start = pos;
    while (pos < body.size() && !space(body[pos])) ++pos;
    if (pos == start) return std::nullopt;
    return body.substr(start, pos - start);
  };
  for (const PlyElement& e : header.elements) {
    for (std::uint64_t i = 0; i < e.count; ++i) {
      for (const PlyProperty& p : e.properties) {
        std::optional<std::string_view> token = next_token();
        if (!token) too_short(path, e, i, "the data ends before it");
        if (p.count_bytes == 0) continue;
        std::optional<std::uint64_t> length = unsigned_number(*token);
        if (!length) return;  // not a length: Assimp reports the syntax error
        if (*length > (body.size() - pos + 1) / 2)  // a digit and a separator each, but the last
          too_short(path, e, i,
                    "a list declares " + std::to_string(*length) + " entries, but only " +
                        std::to_string(body.size() - pos) + " bytes remain");
        for (std::uint64_t k = 0; k < *length; ++k)
          if (!next_token()) too_short(path, e, i, "the data ends inside a list");
      }
    }
  }
}

void check_ply(const std::string& path, std::string_view bytes) {
  PlyHeader header = parse_ply_header(path, bytes);
  std::string_view body = bytes.substr(header.body_offset);
  check_element_counts(path, header, body.size());
  if (header.format == PlyFormat::ascii) walk_ascii_body(path, header, body);
  else walk_binary_body(path, header, body);
}

void check_stl(const std::string& path, std::string_view bytes) {
  std::size_t first = bytes.find_first_not_of(" \t\r\n");
  if (first != std::string_view::npos && bytes.substr(first, 5) == "solid") return;  // ASCII STL
  constexpr std::size_t header_bytes = 84, triangle_bytes = 50;
  if (bytes.size() < header_bytes)
    throw Error(path + ": " + std::to_string(bytes.size()) + " bytes: neither an ASCII STL (which starts with " +
                "'solid') nor a binary STL (at least " + std::to_string(header_bytes) + " bytes)");
  std::uint32_t count = 0;
  for (int i = 3; i >= 0; --i) count = (count << 8) | static_cast<std::uint8_t>(bytes[80 + i]);
  std::uint64_t expected = header_bytes + std::uint64_t(count) * triangle_bytes;
  if (expected != bytes.size())
    throw Error(path + ": binary STL header declares " + std::to_string(count) + " triangles, which take " +
                std::to_string(expected) + " bytes, but the file has " + std::to_string(bytes.size()) + " bytes");
}

}  // namespace

std::vector<std::string> obj_material_libraries(std::string_view text) {
  std::vector<std::string> names;
  for_each_assimp_line(text, true, [&](std::string_view line, std::size_t) {
    std::size_t keyword_end = std::min(line.find_first_of(" \t"), line.size());
    if (line.substr(0, keyword_end) != "mtllib") return true;
    std::size_t name = std::min(line.find_first_not_of(" \t", keyword_end), line.size());
    if (name < line.size()) names.emplace_back(line.substr(name));
    return true;
  });
  return names;
}

void check_mtl_statements(const std::string& what, std::string_view bytes) {
  if (bytes.substr(0, 3) == "\xEF\xBB\xBF") bytes.remove_prefix(3);  // Assimp drops a UTF-8 byte order mark
  for_each_assimp_line(bytes, false, [&](std::string_view line, std::size_t line_number) {
    std::vector<std::string_view> w = words(line);
    if (w.empty() || w[0][0] == '#') return true;
    if (w[0] == "newmtl") return false;
    throw Error(what + ", line " + std::to_string(line_number) + ": '" + std::string(w[0].substr(0, 32)) +
                "' comes before the first newmtl, so it belongs to no material");
  });
}

void check_declared_sizes(const std::string& path, const std::string& extension, std::string_view bytes) {
  if (bytes.empty()) throw Error(path + ": the file is empty");
  if (extension == ".ply") check_ply(path, bytes);
  else if (extension == ".stl") check_stl(path, bytes);
}

}  // namespace rtcl
