#include "render/allocation_limit.h"

#include <cstdlib>
#include <new>

namespace {

thread_local size_t limit = ~size_t(0);

void* allocate(size_t bytes) {
  if (bytes > limit) throw std::bad_alloc();
  for (;;) {
    if (void* p = std::malloc(bytes ? bytes : 1)) return p;
    std::new_handler handler = std::get_new_handler();
    if (!handler) throw std::bad_alloc();
    handler();
  }
}

}  // namespace

namespace morphoflow {

AllocationLimit::AllocationLimit(size_t maxBytes) : previous_(limit) { limit = maxBytes < limit ? maxBytes : limit; }
AllocationLimit::~AllocationLimit() { limit = previous_; }

}  // namespace morphoflow

// The replaceable global allocation functions (every form whose default
// would pair malloc and free differently, so that sanitizers see one pair).
void* operator new(size_t bytes) { return allocate(bytes); }
void* operator new[](size_t bytes) { return allocate(bytes); }
void* operator new(size_t bytes, const std::nothrow_t&) noexcept {
  try {
    return allocate(bytes);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}
void* operator new[](size_t bytes, const std::nothrow_t& tag) noexcept { return operator new(bytes, tag); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, size_t) noexcept { std::free(p); }
void operator delete[](void* p, size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
