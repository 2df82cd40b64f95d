#include "rtcl/cl/program.hpp"

#include <cstdlib>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string_view>

#include "rtcl/error.hpp"

namespace rtcl {

// Generated at build time from kernels/ (cmake/embed_kernels.cmake).
const std::map<std::string_view, std::string_view>& embedded_kernels();

namespace {

std::string read_kernel_file(const std::string& path) {
  if (const char* dir = std::getenv("RTCL_KERNEL_DIR"); dir && *dir) {
    std::ifstream in(std::string(dir) + "/" + path, std::ios::binary);
    if (!in) throw Error("kernel file " + path + ": not found under RTCL_KERNEL_DIR=" + dir);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
  }
  const auto& table = embedded_kernels();
  auto it = table.find(path);
  if (it == table.end()) throw Error("kernel file " + path + ": not embedded in this build of rtcl");
  return std::string(it->second);
}

void inline_includes(const std::string& path, std::set<std::string>& seen, std::string& out) {
  if (!seen.insert(path).second) return;
  static const std::regex include_line(R"(^\s*#\s*include\s*"([^"]+)\"\s*$)");
  std::istringstream lines(read_kernel_file(path));
  std::string line;
  int number = 0;
  out += "#line 1 \"" + path + "\"\n";
  while (std::getline(lines, line)) {
    ++number;
    std::smatch m;
    if (std::regex_match(line, m, include_line)) {
      inline_includes(m[1].str(), seen, out);
      out += "#line " + std::to_string(number + 1) + " \"" + path + "\"\n";
    } else {
      out += line;
      out += '\n';
    }
  }
}

}  // namespace

std::string kernel_source(const std::string& path) {
  std::set<std::string> seen;
  std::string out;
  inline_includes(path, seen, out);
  return out;
}

}  // namespace rtcl
