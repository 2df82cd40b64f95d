// Loops over [0, count) on host threads: contiguous parts (the builders'
// passes over every primitive or vertex) or single indices handed to
// whichever thread is free (work items of uneven size).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

#include "rtcl/huge_pages.hpp"
#include "rtcl/thread_pool.hpp"

namespace rtcl {

// Threads for a pass over count items: at most `threads` (0 = every
// hardware thread), and one more only for every min_per_part items (a
// part's hand-off to a pooled thread and back, microseconds to a spinning
// thread and tens of microseconds to a sleeping one (thread_pool.hpp),
// costs up to as much as a few thousand primitives' work).
inline unsigned part_count(std::size_t count, unsigned threads, std::size_t min_per_part) {
  const unsigned available = threads ? threads : std::max(1u, std::thread::hardware_concurrency());
  return static_cast<unsigned>(std::clamp<std::size_t>(count / std::max<std::size_t>(min_per_part, 1), 1, available));
}

// Calls fn(part, begin, end) for parts contiguous ranges covering [0,
// count) in order, part 0 on the calling thread and each other on a thread of
// its own (run_jobs). After all have returned, rethrows the exception of the
// lowest part that threw, so that an error names the first bad item as a
// serial loop would (each part stops at its first).
template <class Fn>
void for_each_part(std::size_t count, unsigned parts, Fn&& fn) {
  parts = std::max(parts, 1u);
  run_jobs(parts, [&](unsigned part) { fn(part, count * part / parts, count * (part + 1) / parts); });
}

// Calls fn(k) for every k in [0, count), each on whichever of `threads`
// threads (the caller's among them; at most count) takes it next. After all
// have returned, rethrows the exception of the lowest k that threw.
template <class Fn>
void for_each_index(std::size_t count, unsigned threads, Fn&& fn) {
  std::vector<std::exception_ptr> errors(count);
  std::atomic<std::size_t> next{0};
  run_jobs(static_cast<unsigned>(std::min<std::size_t>(std::max(threads, 1u), count)), [&](unsigned) {
    for (std::size_t k; (k = next.fetch_add(1, std::memory_order_relaxed)) < count;) {
      try {
        fn(k);
      } catch (...) {
        errors[k] = std::current_exception();
      }
    }
  });
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

// Reserves room for n elements in v (advised for huge pages, as
// reserve_advised) and faults in the pages of the room beyond v's elements
// on up to `threads` threads, one write per 4 KiB, before any element
// exists there: the resize that follows then writes mapped memory, where
// it would otherwise take every page's first touch (the kernel zeroing the
// page, on a virtual machine often much more) on the calling thread alone.
template <class Vector>
void reserve_faulted(Vector& v, std::size_t n, unsigned threads) {
  reserve_advised(v, n);
  constexpr std::size_t kPage = 4096;
  auto* room = reinterpret_cast<volatile unsigned char*>(v.data() + v.size());
  const std::size_t bytes = (v.capacity() - v.size()) * sizeof(typename Vector::value_type);
  const std::size_t pages = (bytes + kPage - 1) / kPage;
  for_each_part(pages, part_count(pages, threads, 256), [&](unsigned, std::size_t begin, std::size_t end) {
    for (std::size_t page = begin; page < end; ++page) room[page * kPage] = 0;
  });
}

}  // namespace rtcl
