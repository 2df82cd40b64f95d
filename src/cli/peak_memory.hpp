// Peak resident memory of this process over a stretch of code, as `rtcl
// bench` reports it for each build: the kernel's high-water mark (VmHWM)
// is reset to the current resident size on construction (writing 5 to
// /proc/self/clear_refs, Linux 4.0+), after the allocator has returned the
// free memory it kept (malloc_trim), and peak_extra_bytes() is how far it
// rose above that size since: the fresh memory the code touched at most at
// once. On a CPU OpenCL device this includes the
// structure's device buffers, which live in host memory.
#pragma once

#include <cstddef>

namespace rtcl::cli {

class PeakMemory {
 public:
  PeakMemory();
  // Bytes by which the peak resident size rose since construction; 0 when
  // the kernel does not offer the reset (then `available()` is false).
  std::size_t peak_extra_bytes() const;
  bool available() const { return available_; }

 private:
  std::size_t base_ = 0;
  bool available_ = false;
};

}  // namespace rtcl::cli
