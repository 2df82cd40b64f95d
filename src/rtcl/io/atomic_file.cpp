#include "rtcl/io/atomic_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>

#include "rtcl/error.hpp"
#include "rtcl/io/temp_cleanup.hpp"

namespace rtcl {

namespace fs = std::filesystem;

namespace {

std::string errno_text(int err) { return std::strerror(err); }

fs::path directory_of(const std::string& path) {
  fs::path dir = fs::path(path).parent_path();
  return dir.empty() ? fs::path(".") : dir;
}

// The file a write to `path` replaces: `path` itself, or, when it is a
// symbolic link (or a chain of them), the file the link points to, so that
// the link stays a link.
fs::path resolve_target(const std::string& path) {
  fs::path p(path);
  for (int depth = 0; depth < 40; ++depth) {
    std::error_code ec;
    if (!fs::is_symlink(fs::symlink_status(p, ec))) return p;
    fs::path link = fs::read_symlink(p, ec);
    if (ec) throw Error(path + ": cannot read the symbolic link: " + ec.message());
    p = link.is_absolute() ? link : p.parent_path() / link;
  }
  throw Error(path + ": cannot write: too many levels of symbolic links");
}

// Temporary names: "DIR/.STEM.tmp-PID-XXXXXXXX.EXT". The prefix is what
// stale_temp_pid() recognises; the pid says whose it is.
std::string temp_prefix(const fs::path& target) { return "." + target.stem().string() + ".tmp-"; }

// The pid in the name of a temporary file for `target`, or 0 when `name` is
// not one.
pid_t stale_temp_pid(const fs::path& target, const std::string& name) {
  std::string prefix = temp_prefix(target), ext = target.extension().string();
  if (name.rfind(prefix, 0) != 0 || name.size() < prefix.size() + ext.size() ||
      name.compare(name.size() - ext.size(), ext.size(), ext) != 0)
    return 0;
  long pid = std::strtol(name.c_str() + prefix.size(), nullptr, 10);
  return pid > 0 ? static_cast<pid_t>(pid) : 0;
}

// Removes temporary files for `target` left by processes that no longer run
// (killed with SIGKILL, or by a power cut, in the middle of a write).
void remove_stale_temps(const fs::path& target) {
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(directory_of(target.string()), ec)) {
    pid_t pid = stale_temp_pid(target, entry.path().filename().string());
    if (pid > 0 && pid != ::getpid() && ::kill(pid, 0) != 0 && errno == ESRCH) ::unlink(entry.path().c_str());
  }
}

// Creates an empty, new temporary file for `target` (O_EXCL, mode 0666 less
// the umask, like any new output file) and returns its path and descriptor.
// Errors name `path`, the name the user gave.
std::pair<std::string, int> create_temp(const std::string& path, const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  std::random_device entropy;
  fs::path dir = directory_of(target.string());
  for (int attempt = 0; attempt < 100; ++attempt) {
    char tag[40];
    std::snprintf(tag, sizeof tag, "%ld-%08x", static_cast<long>(::getpid()), entropy() ^ (counter++ * 0x9e3779b9u));
    fs::path temp = dir / (temp_prefix(target) + tag + target.extension().string());
    int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) return {temp.string(), fd};
    if (errno != EEXIST) {
      int err = errno;
      if (err == ENOENT) throw Error(path + ": cannot write: directory '" + dir.string() + "' does not exist");
      throw Error(path + ": cannot write in directory '" + dir.string() + "': " + errno_text(err));
    }
  }
  throw Error(path + ": cannot write: no free temporary file name in '" + dir.string() + "'");
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

// Flushes the finished temporary file, gives it the permission bits of the
// file it replaces, renames it over the target and flushes the directory, so
// that after a crash the directory holds the old file or the new one.
void commit(const std::string& temp, const fs::path& target, const std::string& path) {
  struct stat old {};
  if (::stat(target.c_str(), &old) == 0 && S_ISREG(old.st_mode) && ::chmod(temp.c_str(), old.st_mode & 07777) != 0)
    throw Error(path + ": cannot keep the permissions of the existing file: " + errno_text(errno));
  int fd = ::open(temp.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw Error(path + ": the temporary file " + temp + " vanished before it was complete");
  int status = ::fsync(fd);
  int err = errno;
  ::close(fd);
  if (status != 0) throw Error(path + ": flushing to disk failed: " + errno_text(err));
  if (std::rename(temp.c_str(), target.c_str()) != 0)
    throw Error(path + ": cannot replace it with the written file: " + errno_text(errno));
  int dir = ::open(directory_of(target.string()).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir < 0) throw Error(path + ": written, but its directory cannot be opened to flush it: " + errno_text(errno));
  status = ::fsync(dir);
  err = errno;
  ::close(dir);
  if (status != 0 && err != EINVAL) throw Error(path + ": written, but flushing its directory failed: " + errno_text(err));
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
  fs::path target = resolve_target(path);
  remove_stale_temps(target);
  auto [temp, fd] = create_temp(path, target);
  ::close(fd);
  TempCleanup cleanup_on_signal(temp);
  try {
    write(temp);
    commit(temp, target, path);
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
