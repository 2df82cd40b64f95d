#include <cstdlib>
#include <string>

#include "distributed.hpp"
#include "rtcl/error.hpp"

namespace rtcl::cli {

std::optional<int> launcher_world_size() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"})
    if (const char* value = std::getenv(name); value && *value) {
      char* end = nullptr;
      long n = std::strtol(value, &end, 10);
      if (end != value && *end == '\0' && n > 0 && n < (1L << 30)) return static_cast<int>(n);
    }
  return std::nullopt;
}

void refuse_ranks_without_mpi(const std::string& command) {
  if (mpi_supported()) return;
  std::optional<int> size = launcher_world_size();
  if (!size || *size <= 1) return;
  throw Error(command + ": started as one of " + std::to_string(*size) +
              " MPI ranks, but this rtcl was built without MPI support (every rank would do the whole job "
              "alone); install libopenmpi-dev and rebuild with -DRTCL_MPI=ON, or run it without mpirun");
}

}  // namespace rtcl::cli
