// See heap_counter.hpp.
#include "tests/support/heap_counter.hpp"

#include <atomic>
#include <cstdlib>
#include <new>

// Heap allocations are counted by replacing the global operator new and, outside AddressSanitizer
// builds (whose runtime owns malloc), by interposing malloc, calloc and realloc, which is where
// Eigen's dynamic matrices get their memory. The replacements stay out of line so that GCC does
// not pair an inlined new with a free and warn.
namespace {
std::atomic<long> heap_allocations{0};
}  // namespace

__attribute__((noinline)) void* operator new(std::size_t size) {
  ++heap_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
__attribute__((noinline)) void* operator new(std::size_t size, std::align_val_t alignment) {
  ++heap_allocations;
  const std::size_t a = static_cast<std::size_t>(alignment);
  if (void* p = std::aligned_alloc(a, (size + a - 1) / a * a)) return p;
  throw std::bad_alloc();
}
__attribute__((noinline)) void operator delete(void* p) noexcept { std::free(p); }
__attribute__((noinline)) void operator delete(void* p, std::size_t) noexcept { std::free(p); }
__attribute__((noinline)) void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
__attribute__((noinline)) void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

#if !defined(__SANITIZE_ADDRESS__)
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* malloc(std::size_t size) noexcept {
  ++heap_allocations;
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) noexcept {
  ++heap_allocations;
  return __libc_calloc(count, size);
}
void* realloc(void* p, std::size_t size) noexcept {
  ++heap_allocations;
  return __libc_realloc(p, size);
}
}
constexpr bool kMallocCounted = true;
#else
constexpr bool kMallocCounted = false;
#endif

namespace saltus::testing {
long heapAllocations() { return heap_allocations; }
bool mallocCounted() { return kMallocCounted; }
}  // namespace saltus::testing
