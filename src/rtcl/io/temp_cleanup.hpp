// Temporary files removed when the process is stopped by a signal. While a
// TempCleanup is alive, SIGINT, SIGTERM, SIGHUP and SIGQUIT (those whose
// disposition is the default; an ignored signal stays ignored) unlink its
// path and then end the process as the signal would have. SIGKILL cannot be
// caught: the file then stays, under a name that says which process made it
// (see atomic_file.cpp, which removes such leftovers of dead processes).
#pragma once

#include <string>

namespace rtcl {

class TempCleanup {
 public:
  explicit TempCleanup(const std::string& path);  // at most 64 at once, paths below 4096 bytes
  ~TempCleanup();
  TempCleanup(const TempCleanup&) = delete;
  TempCleanup& operator=(const TempCleanup&) = delete;

 private:
  int slot_ = -1;  // -1: not registered (no free slot); the file is then only removed on exceptions
};

}  // namespace rtcl
