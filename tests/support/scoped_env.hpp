// An environment variable set (or unset, with std::nullopt) for one scope,
// and restored at its end: RTCL_DEVICE, RTCL_MAX_ALLOC_BYTES,
// RTCL_HOST_ARRAYS and the like, read when a Device is opened or a call is
// made.
#pragma once

#include <cstdlib>
#include <optional>
#include <string>

namespace rtcl::test {

class ScopedEnv {
 public:
  ScopedEnv(const char* name, std::optional<std::string> value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value)
      ::setenv(name, value->c_str(), 1);
    else
      ::unsetenv(name);
  }
  ~ScopedEnv() {
    if (old_)
      ::setenv(name_, old_->c_str(), 1);
    else
      ::unsetenv(name_);
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

}  // namespace rtcl::test
