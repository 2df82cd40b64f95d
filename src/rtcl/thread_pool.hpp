// Host threads that outlive one parallel loop: starting a thread and joining
// it costs tens of microseconds (more on a virtual machine), paid per loop,
// and a BVH build runs a dozen loops (the boxes, the root's binning and
// partition, the subtrees, the flatten's walk and gather).
//
// A thread that runs out of work spins for kSpinTime before it sleeps:
// waking a sleeping thread costs tens of microseconds per loop against a
// few for a spinning one, and threads that have slept long start a build
// markedly slower than threads kept awake.
#pragma once

#include <chrono>
#include <functional>

namespace rtcl {

// How long a thread out of work spins before it sleeps: longer than the
// serial stretches between a build's parallel loops (a few hundred
// microseconds on meshes of some 100k triangles).
inline constexpr std::chrono::microseconds kSpinTime{1000};

// Polls ready() until it returns true (then true) or kSpinTime has passed
// (then false), pausing the core between polls.
template <class Ready>
bool spin_until(Ready ready) {
  const auto until = std::chrono::steady_clock::now() + kSpinTime;
  for (unsigned polls = 1;; ++polls) {
    if (ready()) return true;
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    asm volatile("yield");
#endif
    if (polls % 64 == 0 && std::chrono::steady_clock::now() >= until) return false;
  }
}

// Runs job(0) .. job(jobs - 1), each on a thread of its own: job 0 on the
// calling thread, the others on threads of a process-wide pool, which starts
// a thread only when none is idle, so that the jobs run at the same time as
// they would on threads started for them (a job may wait for another, and
// may itself call run_jobs). Returns when every job has returned; then
// rethrows the exception of the lowest job that threw. A pool thread whose
// job returned spins (spin_until) for the next one while fewer threads than
// the hardware's are running jobs or spinning; the caller spins for its
// batch's jobs to return before it sleeps.
void run_jobs(unsigned jobs, const std::function<void(unsigned)>& job);

}  // namespace rtcl
