// The message of the rtcl::Error a callable throws.
#pragma once

#include <string>

#include "rtcl/error.hpp"

namespace rtcl::test {

// "" when f throws nothing; other exception types propagate.
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace rtcl::test
