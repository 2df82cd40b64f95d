// Host threads that outlive one parallel loop: starting a thread and joining
// it costs ~75 us on the 2-core development VM, about a tenth of a millisecond
// per loop, and a BVH build runs a dozen loops (the boxes, the root's
// binning and partition, the subtrees, the flatten's walk and gather).
#pragma once

#include <functional>

namespace rtcl {

// Runs job(0) .. job(jobs - 1), each on a thread of its own: job 0 on the
// calling thread, the others on threads of a process-wide pool, which starts
// a thread only when none is idle, so that the jobs run at the same time as
// they would on threads started for them (a job may wait for another, and
// may itself call run_jobs). Returns when every job has returned; then
// rethrows the exception of the lowest job that threw.
void run_jobs(unsigned jobs, const std::function<void(unsigned)>& job);

}  // namespace rtcl
