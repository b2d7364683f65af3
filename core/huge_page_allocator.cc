#include "core/huge_page_allocator.h"

#include <sys/mman.h>

#include <cstdint>

namespace neuralmesh {
namespace {

constexpr size_t kHugePage = size_t{2} << 20;

size_t RoundUpToHugePages(size_t bytes) { return (bytes + kHugePage - 1) & ~(kHugePage - 1); }

}  // namespace

void* AllocateHugePages(size_t bytes) {
  const size_t size = RoundUpToHugePages(bytes);
  // mmap aligns to 4 KB only: map one huge page more and unmap what lies outside the aligned
  // range.
  const size_t mapped = size + kHugePage;
  void* raw = mmap(nullptr, mapped, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) throw std::bad_alloc();
  const uintptr_t begin = reinterpret_cast<uintptr_t>(raw);
  const uintptr_t aligned = (begin + kHugePage - 1) & ~(kHugePage - 1);
  if (aligned > begin) munmap(raw, aligned - begin);
  const uintptr_t tail = aligned + size;
  const uintptr_t end = begin + mapped;
  if (end > tail) munmap(reinterpret_cast<void*>(tail), end - tail);
  void* p = reinterpret_cast<void*>(aligned);
#ifdef MADV_HUGEPAGE
  madvise(p, size, MADV_HUGEPAGE);  // A hint; without transparent huge pages it fails.
#endif
  return p;
}

void AdviseHugePages(const void* begin, size_t bytes) {
  const uintptr_t first = (reinterpret_cast<uintptr_t>(begin) + kHugePage - 1) & ~(kHugePage - 1);
  const uintptr_t last = (reinterpret_cast<uintptr_t>(begin) + bytes) & ~(kHugePage - 1);
  if (last <= first) return;
#ifdef MADV_HUGEPAGE
  void* p = reinterpret_cast<void*>(first);
  if (madvise(p, last - first, MADV_HUGEPAGE) != 0) return;
  constexpr int kMadvCollapse = 25;  // MADV_COLLAPSE; Debian 12's headers predate it.
  madvise(p, last - first, kMadvCollapse);
#endif
}

void FreeHugePages(void* p, size_t bytes) { munmap(p, RoundUpToHugePages(bytes)); }

}  // namespace neuralmesh
