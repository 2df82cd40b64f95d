// rtcl built without MPI: the distributed subcommands are not there.
#include "bench_matrix.hpp"
#include "distributed.hpp"
#include "rtcl/error.hpp"

namespace rtcl::cli {

bool mpi_supported() { return false; }

void render_distributed(const RenderOptions&) { throw Error("rtcl render: this rtcl was built without MPI support"); }

void bench_distributed(const BenchOptions&) { throw Error("rtcl bench: this rtcl was built without MPI support"); }

}  // namespace rtcl::cli
