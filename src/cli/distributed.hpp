// rtcl under mpirun: how the launcher is recognised, and the distributed
// subcommands (src/cli/mpi/, built when CMake finds MPI; without it
// mpi_stub/ answers that this rtcl has no MPI support).
#pragma once

#include <optional>
#include <string>

#include "render_options.hpp"

namespace rtcl::cli {

// The world size an MPI launcher announced in the environment
// (OMPI_COMM_WORLD_SIZE from Open MPI's mpirun, PMI_SIZE from MPICH/Hydra
// and Slurm's PMI), or none when rtcl was not started by one.
std::optional<int> launcher_world_size();

// True when this rtcl was built with MPI.
bool mpi_supported();

// Throws Error when rtcl runs as one of several ranks of an MPI job but was
// built without MPI: each rank would do the whole job alone. `command`
// names the subcommand in the message.
void refuse_ranks_without_mpi(const std::string& command);

// The distributed render: tiles handed out by rank 0, the image written by
// rank 0 (docs/cli.md, "Under mpirun").
void render_distributed(const RenderOptions& o);

}  // namespace rtcl::cli
