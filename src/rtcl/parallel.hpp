// Contiguous parts of a loop over [0, count) on host threads: the builders'
// passes over every primitive or vertex.
#pragma once

#include <algorithm>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace rtcl {

// Threads for a pass over count items: at most `threads` (0 = every
// hardware thread), and one more only for every min_per_part items (a
// thread's start costs about as much as a few thousand primitives' work).
inline unsigned part_count(std::size_t count, unsigned threads, std::size_t min_per_part) {
  const unsigned available = threads ? threads : std::max(1u, std::thread::hardware_concurrency());
  return static_cast<unsigned>(std::clamp<std::size_t>(count / std::max<std::size_t>(min_per_part, 1), 1, available));
}

// Calls fn(part, begin, end) for parts contiguous ranges covering [0,
// count) in order, part 0 on the calling thread and each other on its own
// thread. After all have returned, rethrows the exception of the lowest part
// that threw, so that an error names the first bad item as a serial loop
// would (each part stops at its first).
template <class Fn>
void for_each_part(std::size_t count, unsigned parts, Fn&& fn) {
  parts = std::max(parts, 1u);
  if (parts == 1) {
    fn(0u, std::size_t(0), count);
    return;
  }
  std::vector<std::exception_ptr> errors(parts);
  auto run = [&](unsigned part) {
    try {
      fn(part, count * part / parts, count * (part + 1) / parts);
    } catch (...) {
      errors[part] = std::current_exception();
    }
  };
  std::vector<std::thread> helpers;
  helpers.reserve(parts - 1);
  for (unsigned part = 1; part < parts; ++part) helpers.emplace_back(run, part);
  run(0);
  for (std::thread& helper : helpers) helper.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace rtcl
