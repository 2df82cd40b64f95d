// The one place the OpenCL C++ bindings are configured: OpenCL 1.2, with
// exceptions (cl::Error names the failed call). Include this, never
// <CL/opencl.hpp> directly.
#pragma once

#ifndef CL_HPP_TARGET_OPENCL_VERSION
#define CL_HPP_TARGET_OPENCL_VERSION 120
#endif
#ifndef CL_HPP_MINIMUM_OPENCL_VERSION
#define CL_HPP_MINIMUM_OPENCL_VERSION 120
#endif
#ifndef CL_HPP_ENABLE_EXCEPTIONS
#define CL_HPP_ENABLE_EXCEPTIONS
#endif
#include <CL/opencl.hpp>

#include <string>
#include <utility>

#include "rtcl/error.hpp"

namespace rtcl {

template <class F>
decltype(auto) with_cl_errors(F&& f) {
  try {
    return std::forward<F>(f)();
  } catch (const cl::Error& e) {
    throw Error(std::string(e.what()) + " failed: " + cl_error_name(e.err()) + " (" +
                std::to_string(e.err()) + ")" + cl_error_hint(e.err()));
  }
}

}  // namespace rtcl
