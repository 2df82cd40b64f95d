#include "rtcl/cl/program.hpp"

#include <cstdlib>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string_view>
#include <utility>
#include <vector>

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

bool kernel_file_exists(const std::string& path) {
  if (const char* dir = std::getenv("RTCL_KERNEL_DIR"); dir && *dir)
    return std::ifstream(std::string(dir) + "/" + path).good();
  return embedded_kernels().count(path) > 0;
}

// The file `#include "name"` in `from` names: beside `from` when there is
// one (as a C preprocessor looks first), else relative to kernels/.
std::string included_path(const std::string& from, const std::string& name) {
  std::size_t slash = from.rfind('/');
  if (slash != std::string::npos) {
    std::string beside = from.substr(0, slash + 1) + name;
    if (kernel_file_exists(beside)) return beside;
  }
  return name;
}

void inline_includes(const std::string& path, const std::string& text, std::set<std::string>& seen,
                     std::string& out);

void inline_includes(const std::string& path, std::set<std::string>& seen, std::string& out) {
  if (seen.count(path)) return;
  inline_includes(path, read_kernel_file(path), seen, out);
}

void inline_includes(const std::string& path, const std::string& text, std::set<std::string>& seen,
                     std::string& out) {
  seen.insert(path);
  static const std::regex include_line(R"(^\s*#\s*include\s*"([^"]+)\"\s*$)");
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  out += "#line 1 \"" + path + "\"\n";
  while (std::getline(lines, line)) {
    ++number;
    std::smatch m;
    if (std::regex_match(line, m, include_line)) {
      inline_includes(included_path(path, m[1].str()), seen, out);
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

std::string kernel_source(const std::string& path, const std::string& text) {
  std::set<std::string> seen;
  std::string out;
  inline_includes(path, text, seen, out);
  return out;
}

std::string name_source_lines(const std::string& log, const std::string& source) {
  // origin[k]: the file and line of the assembled source's line k + 1
  static const std::regex line_marker(R"re(^#line (\d+) "([^"]+)"$)re");
  std::vector<std::pair<std::string, long>> origin;
  std::istringstream lines(source);
  std::string line, file;
  long next = 0;
  while (std::getline(lines, line)) {
    std::smatch m;
    if (std::regex_match(line, m, line_marker)) {
      origin.emplace_back(std::string(), 0);
      file = m[2].str();
      next = std::stol(m[1].str());
    } else {
      origin.emplace_back(file, next);
      if (!file.empty()) ++next;
    }
  }
  static const std::regex position(R"(<(kernel|source)>:(\d+):)");
  std::string out;
  auto last = log.cbegin();
  for (std::sregex_iterator it(log.begin(), log.end(), position), end; it != end; ++it) {
    const std::smatch& m = *it;
    out.append(last, m[0].first);
    std::size_t k = std::stoul(m[2].str());
    if (k >= 1 && k <= origin.size() && !origin[k - 1].first.empty())
      out += origin[k - 1].first + ":" + std::to_string(origin[k - 1].second) + ":";
    else
      out += m[0].str();
    last = m[0].second;
  }
  out.append(last, log.cend());
  return out;
}

}  // namespace rtcl
