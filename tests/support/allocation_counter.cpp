#include "allocation_counter.h"

#include <malloc.h>

#include <atomic>
#include <cstdlib>
#include <new>

long g_allocations = 0;
long g_mallocs = 0;
long g_fail_allocation = 0;

namespace {
// Heap bytes in use by the malloc family (usable sizes) and their peak; atomic
// because tests with threads allocate concurrently.
std::atomic<long> g_heap_bytes{0};
std::atomic<long> g_heap_peak{0};

void Added(long bytes) {
  const long now = g_heap_bytes.fetch_add(bytes, std::memory_order_relaxed) + bytes;
  long peak = g_heap_peak.load(std::memory_order_relaxed);
  while (now > peak && !g_heap_peak.compare_exchange_weak(peak, now, std::memory_order_relaxed)) {
  }
}
void Allocated(void* p) {
  if (p != nullptr) Added(static_cast<long>(malloc_usable_size(p)));
}
void Freed(void* p) {
  if (p != nullptr) Added(-static_cast<long>(malloc_usable_size(p)));
}
}  // namespace

long HeapBytesInUse() { return g_heap_bytes.load(std::memory_order_relaxed); }
long HeapBytesPeak() { return g_heap_peak.load(std::memory_order_relaxed); }
void ResetHeapBytesPeak() { g_heap_peak.store(HeapBytesInUse(), std::memory_order_relaxed); }

// glibc's own entry points do the work of the replaced malloc family.
extern "C" void* __libc_malloc(std::size_t);
extern "C" void* __libc_calloc(std::size_t, std::size_t);
extern "C" void* __libc_realloc(void*, std::size_t);
extern "C" void __libc_free(void*);

extern "C" void* malloc(std::size_t n) noexcept {
  ++g_mallocs;
  void* p = __libc_malloc(n);
  Allocated(p);
  return p;
}
extern "C" void* calloc(std::size_t n, std::size_t size) noexcept {
  ++g_mallocs;
  void* p = __libc_calloc(n, size);
  Allocated(p);
  return p;
}
extern "C" void* realloc(void* p, std::size_t n) noexcept {
  ++g_mallocs;
  const long before = p != nullptr ? static_cast<long>(malloc_usable_size(p)) : 0;
  void* q = __libc_realloc(p, n);
  if (q == nullptr) {  // failed (the old block stays), or n == 0 freed it
    if (n == 0) Added(-before);
    return q;
  }
  // Moved: both blocks existed at once (counted so in the peak).
  if (q != p) {
    Added(static_cast<long>(malloc_usable_size(q)));
    Added(-before);
  } else {
    Added(static_cast<long>(malloc_usable_size(q)) - before);
  }
  return q;
}
extern "C" void free(void* p) noexcept {
  Freed(p);
  __libc_free(p);
}

// GCC cannot see that these replacements pair malloc with free.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) {
  ++g_allocations;
  if (g_fail_allocation > 0 && --g_fail_allocation == 0) throw std::bad_alloc();
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
