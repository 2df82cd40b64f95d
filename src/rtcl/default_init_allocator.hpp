// An allocator whose value-less construct() default-initialises: a
// std::vector<T, DefaultInitAllocator<T>> of a trivial T grows by resize()
// without writing the new elements, for arrays that are filled right after
// (in parallel, so that the first touch of their pages is shared too).
// Large arrays are advised for huge pages before that touch
// (rtcl/huge_pages.hpp).
#pragma once

#include <memory>
#include <new>
#include <type_traits>
#include <utility>

#include "rtcl/huge_pages.hpp"

namespace rtcl {

template <class T>
class DefaultInitAllocator : public std::allocator<T> {
 public:
  template <class U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };

  DefaultInitAllocator() = default;
  template <class U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    T* p = std::allocator<T>::allocate(n);
    advise_huge_pages(p, n * sizeof(T));
    return p;
  }

  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

}  // namespace rtcl
