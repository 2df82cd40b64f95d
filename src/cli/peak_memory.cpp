#include "peak_memory.hpp"

#include <malloc.h>

#include <cstdlib>
#include <fstream>
#include <string>

namespace rtcl::cli {

namespace {

// The "Key:  N kB" line of /proc/self/status, in bytes; 0 when absent.
std::size_t status_bytes(const std::string& key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key + ":", 0) == 0) return std::strtoull(line.c_str() + key.size() + 1, nullptr, 10) * 1024;
  return 0;
}

}  // namespace

PeakMemory::PeakMemory() {
  // Free memory the allocator kept (glibc keeps freed blocks below its
  // mmap threshold, which grows to 32 MB after large frees): a build that
  // reused it would not raise the resident size, and its peak would read
  // low.
  malloc_trim(0);
  std::ofstream reset("/proc/self/clear_refs");
  reset << "5";
  reset.flush();
  available_ = reset.good();
  base_ = status_bytes("VmRSS");
  available_ = available_ && base_ > 0 && status_bytes("VmHWM") <= base_ + (std::size_t(1) << 20);
}

std::size_t PeakMemory::peak_extra_bytes() const {
  if (!available_) return 0;
  std::size_t peak = status_bytes("VmHWM");
  return peak > base_ ? peak - base_ : 0;
}

}  // namespace rtcl::cli
