#include "rtcl/io/atomic_file.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "rtcl/error.hpp"
#include "support/error_of.hpp"
#include "support/temp_dir.hpp"

namespace rtcl::test {
namespace {

std::span<const std::byte> bytes_of(const std::string& s) { return std::as_bytes(std::span(s.data(), s.size())); }


TEST(AtomicFile, WritesAndReplacesWholeFiles) {
  TempDir dir;
  std::string path = dir.file("out.bin");
  write_file_atomically(path, bytes_of("first"));
  EXPECT_EQ(read_text(path), "first");
  write_file_atomically(path, bytes_of("second, longer"));
  EXPECT_EQ(read_text(path), "second, longer");
  write_file_atomically(path, bytes_of(""));
  EXPECT_EQ(read_text(path), "");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.bin"});
}

TEST(AtomicFile, CallbackWritesATempFileBesideTheTargetWithItsExtension) {
  TempDir dir;
  std::string path = dir.file("image.png"), seen;
  write_file_atomically(path, [&](const std::string& temp) {
    seen = temp;
    EXPECT_EQ(temp.rfind(dir.path() + "/", 0), 0u) << temp;
    EXPECT_EQ(temp.substr(temp.size() - 4), ".png") << temp;
    EXPECT_FALSE(std::ifstream(path).good()) << "the target appears only after the writer is done";
    std::ofstream(temp) << "pixels";
  });
  EXPECT_EQ(read_text(path), "pixels");
  EXPECT_FALSE(std::ifstream(seen).good()) << "the temporary name is gone";
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"image.png"});
}

TEST(AtomicFile, AFailingWriterLeavesTheOldFileAndNoTemporary) {
  TempDir dir;
  std::string path = dir.write("keep.txt", "old content");
  EXPECT_THROW(write_file_atomically(path,
                                     [](const std::string& temp) {
                                       std::ofstream(temp) << "half";
                                       throw std::runtime_error("encoder failed");
                                     }),
               std::runtime_error);
  EXPECT_EQ(read_text(path), "old content");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.txt"});
}

TEST(AtomicFile, UnwritableTargetsAreClearErrors) {
  TempDir dir;
  std::string nowhere = dir.file("no/such/dir/out.hits");
  std::string e = error_of([&] { write_file_atomically(nowhere, bytes_of("x")); });
  EXPECT_NE(e.find(nowhere + ": cannot write: directory"), std::string::npos) << e;
  EXPECT_NE(e.find("does not exist"), std::string::npos) << e;
  e = error_of([&] { check_writable(nowhere); });
  EXPECT_NE(e.find("does not exist"), std::string::npos) << e;
  // a directory in the way of the target
  std::string sub = dir.file("sub");
  std::filesystem::create_directory(sub);
  e = error_of([&] { write_file_atomically(sub, bytes_of("x")); });
  EXPECT_NE(e.find(sub + ": cannot replace it"), std::string::npos) << e;
  e = error_of([&] { check_writable(sub); });
  EXPECT_NE(e.find("it is a directory"), std::string::npos) << e;
  // a file where a directory should be
  std::string file = dir.write("plain", "x");
  e = error_of([&] { check_writable(file + "/out.hits"); });
  EXPECT_NE(e.find("is not a directory"), std::string::npos) << e;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"plain", "sub"})) << "no temporary file is left";
  EXPECT_EQ(error_of([&] { check_writable(dir.file("fine.hits")); }), "");
}

mode_t permissions(const std::string& path) {
  struct stat st {};
  EXPECT_EQ(::stat(path.c_str(), &st), 0) << path;
  return st.st_mode & 07777;
}

TEST(AtomicFile, ASymlinkTargetReplacesTheFileItPointsTo) {
  TempDir dir;
  std::filesystem::create_directory(dir.file("data"));
  std::string real = dir.write("data/real.hits", "old");
  std::filesystem::create_symlink("data/real.hits", dir.file("link.hits"));   // relative to the link's directory
  std::filesystem::create_symlink(dir.file("link.hits"), dir.file("chain.hits"));  // a link to a link
  write_file_atomically(dir.file("link.hits"), bytes_of("new"));
  EXPECT_TRUE(std::filesystem::is_symlink(dir.file("link.hits")));
  EXPECT_EQ(read_text(real), "new");
  write_file_atomically(dir.file("chain.hits"), bytes_of("newer"));
  EXPECT_TRUE(std::filesystem::is_symlink(dir.file("chain.hits")));
  EXPECT_TRUE(std::filesystem::is_symlink(dir.file("link.hits")));
  EXPECT_EQ(read_text(real), "newer");
  // a dangling link: the file it names is created
  std::filesystem::create_symlink("data/absent.hits", dir.file("dangling.hits"));
  write_file_atomically(dir.file("dangling.hits"), bytes_of("created"));
  EXPECT_TRUE(std::filesystem::is_symlink(dir.file("dangling.hits")));
  EXPECT_EQ(read_text(dir.file("data/absent.hits")), "created");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"chain.hits", "dangling.hits", "data", "link.hits"}));
  // the temporary file lived beside the real file, and is gone
  for (const auto& entry : std::filesystem::directory_iterator(dir.file("data")))
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
}

TEST(AtomicFile, AnExistingFileKeepsItsPermissionBits) {
  TempDir dir;
  std::string path = dir.write("out.hits", "old");
  for (mode_t mode : {0640, 0600, 0754}) {
    ASSERT_EQ(::chmod(path.c_str(), mode), 0);
    write_file_atomically(path, bytes_of("new"));
    EXPECT_EQ(permissions(path), mode);
  }
  mode_t mask = ::umask(022);
  ::umask(mask);
  write_file_atomically(dir.file("fresh.hits"), bytes_of("x"));
  EXPECT_EQ(permissions(dir.file("fresh.hits")), 0666 & ~mask);
}

// A child process writes half of a new file in the middle of an atomic write
// and waits; the test then delivers `signal_number` and returns the child's
// pid after it has ended.
pid_t writer_stopped_by(int signal_number, const std::string& path) {
  int ready[2];
  EXPECT_EQ(::pipe(ready), 0);
  pid_t pid = ::fork();
  if (pid == 0) {
    ::close(ready[0]);
    write_file_atomically(path, [&](const std::string& temp) {
      std::ofstream(temp) << "half of the new";
      char byte = 1;
      if (::write(ready[1], &byte, 1) != 1) ::_exit(3);
      for (;;) ::pause();
    });
    ::_exit(2);  // never reached: the signal ends the process
  }
  ::close(ready[1]);
  char byte = 0;
  EXPECT_EQ(::read(ready[0], &byte, 1), 1) << "the writer never got to the middle of its write";
  ::close(ready[0]);
  ::kill(pid, signal_number);
  int status = 0;
  EXPECT_EQ(::waitpid(pid, &status, 0), pid);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal_number)
      << "the writer should end by the signal, status " << status;
  return pid;
}

TEST(AtomicFile, AWriterStoppedBySigtermOrSigintLeavesTheOldFileAndNoTemporary) {
  for (int signal_number : {SIGTERM, SIGINT}) {
    TempDir dir;
    std::string path = dir.write("out.hits", "old");
    writer_stopped_by(signal_number, path);
    EXPECT_EQ(read_text(path), "old") << strsignal(signal_number);
    EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.hits"}) << strsignal(signal_number);
  }
}

TEST(AtomicFile, AWriterKilledWithSigkillLeavesTheOldFileAndATemporaryTheNextWriteRemoves) {
  TempDir dir;
  std::string path = dir.write("out.hits", "old");
  pid_t pid = writer_stopped_by(SIGKILL, path);
  EXPECT_EQ(read_text(path), "old");
  std::vector<std::string> left = dir.entries();
  ASSERT_EQ(left.size(), 2u) << "SIGKILL cannot be caught: the temporary file stays";
  EXPECT_EQ(left[0].rfind(".out.tmp-" + std::to_string(pid) + "-", 0), 0u) << left[0] << " names its writer";
  write_file_atomically(path, bytes_of("new"));
  EXPECT_EQ(read_text(path), "new");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.hits"}) << "the dead writer's temporary file is removed";
}

}  // namespace
}  // namespace rtcl::test
