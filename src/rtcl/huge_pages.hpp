// Transparent huge pages for the builders' large host arrays. On a host
// whose page faults are dear (a virtual machine, where faulting 4 KiB
// pages in can take a sizeable share of a multi-million-triangle build),
// an array advised before its first touch is faulted in 2 MiB pages
// instead, where the kernel allows them (Linux, transparent_hugepage
// `madvise` or `always`); elsewhere the advice is a no-op. And the other
// way: pages of a consumed array handed back before the array is freed.
#pragma once

#include <cstddef>

namespace rtcl {

// Arrays from this size up are advised.
inline constexpr std::size_t kHugePageAdviceBytes = std::size_t{4} << 20;

// Advises the whole 2 MiB pages inside [data, data + bytes) for huge pages
// when bytes >= kHugePageAdviceBytes; call before the first write. Never
// fails (the advice is a hint).
void advise_huge_pages(void* data, std::size_t bytes) noexcept;

// Reserves room for n elements in an empty vector and advises it (so
// that the resize or fill that follows touches huge pages).
// Gives the whole pages inside [data, data + bytes) back to the operating
// system (Linux: MADV_DONTNEED; elsewhere a no-op): for an array the caller
// no longer reads and frees soon, so that its resident size falls part by
// part as it is consumed. The range's contents are unspecified afterwards
// (zero on Linux); the allocation stays valid to free. Never fails.
void discard_pages(void* data, std::size_t bytes) noexcept;

// Hands the memory the C library's allocator holds free back to the
// operating system (glibc: malloc_trim(0); elsewhere a no-op): for a build
// whose worker threads freed large temporaries in their own allocator
// arenas, which the next phase, on another thread, cannot reuse; without
// it the freed pages stay resident and add to the build's peak. It walks
// every arena's free blocks: for large builds, not per call.
void release_free_heap_memory() noexcept;

template <class Vector>
void reserve_advised(Vector& v, std::size_t n) {
  v.reserve(n);
  advise_huge_pages(v.data(), v.capacity() * sizeof(typename Vector::value_type));
}

}  // namespace rtcl
