#include "rtcl/io/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>

#include "rtcl/error.hpp"

namespace rtcl {

namespace fs = std::filesystem;

namespace {

std::string errno_text(int err) { return std::strerror(err); }

fs::path directory_of(const std::string& path) {
  fs::path dir = fs::path(path).parent_path();
  return dir.empty() ? fs::path(".") : dir;
}

// Creates an empty, new file "DIR/.STEM.tmp-XXXXXXXX.EXT" (O_EXCL, mode 0666
// less the umask, like any new output file) and returns its path and
// descriptor.
std::pair<std::string, int> create_temp(const std::string& path) {
  fs::path target(path);
  std::string stem = target.stem().string(), ext = target.extension().string();
  static std::atomic<unsigned> counter{0};
  std::random_device entropy;
  for (int attempt = 0; attempt < 100; ++attempt) {
    char tag[16];
    std::snprintf(tag, sizeof tag, "%08x", entropy() ^ (counter++ * 0x9e3779b9u));
    fs::path temp = directory_of(path) / ("." + stem + ".tmp-" + tag + ext);
    int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) return {temp.string(), fd};
    if (errno != EEXIST) {
      int err = errno;
      if (err == ENOENT)
        throw Error(path + ": cannot write: directory '" + directory_of(path).string() + "' does not exist");
      throw Error(path + ": cannot write in directory '" + directory_of(path).string() + "': " + errno_text(err));
    }
  }
  throw Error(path + ": cannot write: no free temporary file name in '" + directory_of(path).string() + "'");
}

void write_all(int fd, std::span<const std::byte> bytes, const std::string& path) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw Error(path + ": write failed after " + std::to_string(done) + " of " + std::to_string(bytes.size()) +
                  " bytes: " + errno_text(n < 0 ? errno : EIO));
    done += static_cast<std::size_t>(n);
  }
}

// Flushes the finished temporary file and renames it over the target.
void commit(const std::string& temp, const std::string& path) {
  int fd = ::open(temp.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw Error(path + ": the temporary file " + temp + " vanished before it was complete");
  int status = ::fsync(fd);
  int err = errno;
  ::close(fd);
  if (status != 0) throw Error(path + ": flushing to disk failed: " + errno_text(err));
  if (std::rename(temp.c_str(), path.c_str()) != 0)
    throw Error(path + ": cannot replace it with the written file: " + errno_text(errno));
}

}  // namespace

void write_file_atomically(const std::string& path, std::span<const std::byte> bytes) {
  write_file_atomically(path, [&](const std::string& temp) {
    int fd = ::open(temp.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
    if (fd < 0) throw Error(path + ": cannot open temporary file " + temp + ": " + errno_text(errno));
    try {
      write_all(fd, bytes, path);
    } catch (...) {
      ::close(fd);
      throw;
    }
    if (::close(fd) != 0) throw Error(path + ": write failed: " + errno_text(errno));
  });
}

void write_file_atomically(const std::string& path, const std::function<void(const std::string&)>& write) {
  auto [temp, fd] = create_temp(path);
  ::close(fd);
  try {
    write(temp);
    commit(temp, path);
  } catch (...) {
    ::unlink(temp.c_str());
    throw;
  }
}

void check_writable(const std::string& path) {
  fs::path dir = directory_of(path);
  std::error_code ec;
  if (!fs::exists(dir, ec)) throw Error(path + ": cannot write: directory '" + dir.string() + "' does not exist");
  if (!fs::is_directory(dir, ec)) throw Error(path + ": cannot write: '" + dir.string() + "' is not a directory");
  if (::access(dir.c_str(), W_OK) != 0)
    throw Error(path + ": cannot write in directory '" + dir.string() + "': " + errno_text(errno));
  if (fs::is_directory(path, ec)) throw Error(path + ": cannot write: it is a directory");
}

}  // namespace rtcl
