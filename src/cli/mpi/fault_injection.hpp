// A test hook: RTCL_MPI_FAULT=KIND:RANK makes rank RANK fail when it gets
// its first job, to exercise the fault handling of a distributed run.
// KIND error: the job throws (as a device error would) after it ran;
// kill: the rank sends itself SIGKILL before it runs the job.
#pragma once

namespace rtcl::cli {

enum class FaultKind { none, error, kill };

struct Fault {
  FaultKind kind = FaultKind::none;
  int rank = -1;
};

// The fault RTCL_MPI_FAULT asks for; none when unset. Throws Error naming
// the variable when it is set but not KIND:RANK.
Fault fault_from_environment();

}  // namespace rtcl::cli
