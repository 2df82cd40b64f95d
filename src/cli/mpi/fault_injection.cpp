#include "mpi/fault_injection.hpp"

#include <cstdlib>
#include <string>

#include "rtcl/error.hpp"

namespace rtcl::cli {

Fault fault_from_environment() {
  const char* value = std::getenv("RTCL_MPI_FAULT");
  if (!value || !*value) return {};
  std::string text = value;
  std::size_t colon = text.find(':');
  Fault f;
  std::string kind = text.substr(0, colon);
  if (kind == "error") f.kind = FaultKind::error;
  else if (kind == "kill") f.kind = FaultKind::kill;
  char* end = nullptr;
  long rank = colon == std::string::npos ? -1 : std::strtol(text.c_str() + colon + 1, &end, 10);
  if (f.kind == FaultKind::none || rank < 0 || !end || *end != '\0' || end == text.c_str() + colon + 1)
    throw Error("RTCL_MPI_FAULT=" + text + ": must be error:RANK or kill:RANK");
  f.rank = static_cast<int>(rank);
  return f;
}

}  // namespace rtcl::cli
