// Errors a user can act on: every message names the input and what is wrong.
#pragma once

#include <stdexcept>
#include <string>

namespace rtcl {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Throws Error("CALL failed: CL_NAME (code)" + hint) unless status is CL_SUCCESS.
void check_cl(int status, const char* call);

// "CL_OUT_OF_RESOURCES" for -5; "unknown OpenCL error" otherwise.
const char* cl_error_name(int status);

// What a user can do about the error, starting with "; " ("" when nothing
// specific): for the out-of-memory codes (CL_MEM_OBJECT_ALLOCATION_FAILURE,
// CL_OUT_OF_RESOURCES, CL_OUT_OF_HOST_MEMORY), a smaller job or another device.
const char* cl_error_hint(int status);

}  // namespace rtcl
