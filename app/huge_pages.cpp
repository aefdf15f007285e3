// naris's large C++ arrays ask for transparent huge pages. On this kind of (virtual) machine the
// kernel's fault per 4 KiB page was a third of `naris mesh` on a 4 M-cell mesh, in the arrays
// its improvement, quality and check stages fill once (docs/results/mesh-speed.md); the kernel
// leaves huge pages to regions advised so (THP "madvise" mode, Debian's default).
// Left out under AddressSanitizer, whose own operator new checks new/delete pairs.
#ifndef __SANITIZE_ADDRESS__
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <new>

namespace {

constexpr std::size_t kLarge = std::size_t{4} << 20;  // two huge pages and more

void* allocate(std::size_t bytes) {
  void* p = std::malloc(bytes == 0 ? 1 : bytes);
  if (p == nullptr) throw std::bad_alloc();
  if (bytes >= kLarge) {
    static const std::uintptr_t page = static_cast<std::uintptr_t>(sysconf(_SC_PAGESIZE));
    const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(p) + page - 1) & ~(page - 1);
    const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(page - 1);
    // Advice only: where the kernel declines, the memory is the same, in small pages.
    madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
  }
  return p;
}

}  // namespace

void* operator new(std::size_t bytes) {
  return allocate(bytes);
}
void* operator new[](std::size_t bytes) {
  return allocate(bytes);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
#endif
