#pragma once
// A counting replacement of the global operator new, in all its forms, for the programs that
// show that a step or a solve allocates nothing (the chapter-6 benchmark, the allocation tests of
// chapters 5 and 6). Include it in exactly one source file of an executable: it defines the
// replaceable allocation functions, which then count every heap allocation of the program
// (Eigen's aligned ones and the standard library's included).

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <new>

namespace grbd::demo {

namespace detail {
inline std::atomic<long> allocation_count{0};

inline void* counted_allocation(std::size_t size, std::size_t alignment = 0) {
  allocation_count.fetch_add(1, std::memory_order_relaxed);
  if (size == 0) size = 1;
  void* p = nullptr;
  if (alignment > alignof(std::max_align_t)) {
    p = std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
  } else {
    p = std::malloc(size);
  }
  if (p == nullptr) throw std::bad_alloc();
  return p;
}
}  // namespace detail

/// Heap allocations through operator new since the program started.
inline long allocations() { return detail::allocation_count.load(std::memory_order_relaxed); }

}  // namespace grbd::demo

void* operator new(std::size_t size) { return grbd::demo::detail::counted_allocation(size); }
void* operator new[](std::size_t size) { return grbd::demo::detail::counted_allocation(size); }
void* operator new(std::size_t size, std::align_val_t a) {
  return grbd::demo::detail::counted_allocation(size, static_cast<std::size_t>(a));
}
void* operator new[](std::size_t size, std::align_val_t a) {
  return grbd::demo::detail::counted_allocation(size, static_cast<std::size_t>(a));
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return grbd::demo::detail::counted_allocation(size);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return grbd::demo::detail::counted_allocation(size);
  } catch (...) {
    return nullptr;
  }
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
