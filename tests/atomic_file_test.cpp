#include "rtcl/io/atomic_file.hpp"

#include <gtest/gtest.h>

#include <cstddef>
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

}  // namespace
}  // namespace rtcl::test
