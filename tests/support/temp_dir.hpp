// A fresh directory under the system temp directory, removed with its
// contents when the object goes out of scope; for tests that write files.
#pragma once

#include <string>
#include <vector>

namespace rtcl::test {

class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::string& path() const { return path_; }
  // path() + "/" + name
  std::string file(const std::string& name) const;
  // Writes `content` to file(name) and returns that path.
  std::string write(const std::string& name, const std::string& content) const;
  // Names of the entries in the directory, sorted.
  std::vector<std::string> entries() const;

 private:
  std::string path_;
};

// The whole content of a file ("" when it cannot be read).
std::string read_text(const std::string& path);

}  // namespace rtcl::test
