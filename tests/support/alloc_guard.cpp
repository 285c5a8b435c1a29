// Test support: allocation hooks. Linked into every test executable.
#include "alloc_guard.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cerrno>
#include <cstdlib>
#include <new>

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);
}

namespace {

thread_local int active_depth = 0;
thread_local std::size_t recorded = 0;

inline void note_allocation() {
  if (active_depth > 0)
    ++recorded;
}

[[maybe_unused]] void* aligned(std::size_t alignment, std::size_t size) {
  if (alignment < sizeof(void*))
    alignment = sizeof(void*);
  return __libc_memalign(alignment, size ? size : 1);
}

}  // namespace

#if defined(ARBOR_SANITIZE)
// ---- sanitizer builds (scripts/sanitize.sh) ------------------------------------------------------
// AddressSanitizer owns malloc and operator new: the allocations are counted by its hook instead
// of by interposition (the same count: every malloc, calloc, realloc, aligned and C++ allocation).
// (declared here: GCC's libasan exports it, but only clang ships sanitizer/allocator_interface.h)
extern "C" int __sanitizer_install_malloc_and_free_hooks(
    void (*malloc_hook)(const volatile void*, std::size_t), void (*free_hook)(const volatile void*));
namespace {
void count_hook(const volatile void*, std::size_t) {
  note_allocation();
}
[[maybe_unused]] const int hooks_installed =
    __sanitizer_install_malloc_and_free_hooks(count_hook, nullptr);
}  // namespace
#else
// ---- C allocation functions, interposed over glibc's -----------------------------------------
extern "C" {
void* malloc(std::size_t n) {
  note_allocation();
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t m) {
  note_allocation();
  return __libc_calloc(n, m);
}
void* realloc(void* p, std::size_t n) {
  note_allocation();
  return __libc_realloc(p, n);
}
void free(void* p) {
  __libc_free(p);
}
void* aligned_alloc(std::size_t alignment, std::size_t n) {
  note_allocation();
  return aligned(alignment, n);
}
void* memalign(std::size_t alignment, std::size_t n) {
  note_allocation();
  return aligned(alignment, n);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t n) {
  note_allocation();
  void* p = aligned(alignment, n);
  if (!p)
    return ENOMEM;
  *out = p;
  return 0;
}
}

// ---- C++ operator new / delete ---------------------------------------------------------------
namespace {
void* checked_new(std::size_t n) {
  note_allocation();
  void* p = __libc_malloc(n ? n : 1);
  if (!p)
    std::abort();
  return p;
}
void* checked_new_aligned(std::size_t n, std::align_val_t a) {
  note_allocation();
  void* p = aligned(static_cast<std::size_t>(a), n);
  if (!p)
    std::abort();
  return p;
}
}  // namespace

void* operator new(std::size_t n) {
  return checked_new(n);
}
void* operator new[](std::size_t n) {
  return checked_new(n);
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  return checked_new(n);
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  return checked_new(n);
}
void* operator new(std::size_t n, std::align_val_t a) {
  return checked_new_aligned(n, a);
}
void* operator new[](std::size_t n, std::align_val_t a) {
  return checked_new_aligned(n, a);
}
void operator delete(void* p) noexcept {
  __libc_free(p);
}
void operator delete[](void* p) noexcept {
  __libc_free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  __libc_free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  __libc_free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
  __libc_free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
  __libc_free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  __libc_free(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  __libc_free(p);
}
#endif  // ARBOR_SANITIZE

namespace arbor::test {

std::size_t guarded_allocations() {
  return recorded;
}

NoAllocScope::NoAllocScope() : start_(recorded) {
#ifdef EIGEN_RUNTIME_NO_MALLOC
  eigen_was_allowed_ = Eigen::internal::is_malloc_allowed();
  Eigen::internal::set_is_malloc_allowed(false);
#else
  eigen_was_allowed_ = true;
#endif
  ++active_depth;
}

NoAllocScope::~NoAllocScope() {
  --active_depth;
#ifdef EIGEN_RUNTIME_NO_MALLOC
  Eigen::internal::set_is_malloc_allowed(eigen_was_allowed_);
#endif
  const std::size_t n = recorded - start_;
  if (n != 0) {
    ADD_FAILURE() << n << " heap allocation(s) inside a no-allocation scope";
  }
}

std::size_t NoAllocScope::count() const {
  return recorded - start_;
}

}  // namespace arbor::test
