#include "core/huge_page_allocator.h"

#include <sys/mman.h>

#include <cstdint>

namespace neuralmesh {
namespace {

constexpr size_t kHugePage = size_t{2} << 20;

uintptr_t AlignUp(uintptr_t x) { return (x + kHugePage - 1) & ~(kHugePage - 1); }
uintptr_t AlignDown(uintptr_t x) { return x & ~(kHugePage - 1); }

// Marks [p, p + bytes) (whole huge pages) for transparent huge pages; whether it worked.
bool MarkForHugePages(void* p, size_t bytes) {
#ifdef MADV_HUGEPAGE
  return madvise(p, bytes, MADV_HUGEPAGE) == 0;  // Fails without transparent huge pages.
#else
  return false;
#endif
}

}  // namespace

void* AllocateHugePages(size_t bytes) {
  const size_t size = AlignUp(bytes);
  // mmap aligns to 4 KB only: map one huge page more and unmap what lies outside the aligned
  // range.
  const size_t mapped = size + kHugePage;
  void* raw = mmap(nullptr, mapped, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) throw std::bad_alloc();
  const uintptr_t begin = reinterpret_cast<uintptr_t>(raw);
  const uintptr_t aligned = AlignUp(begin);
  if (aligned > begin) munmap(raw, aligned - begin);
  const uintptr_t tail = aligned + size;
  const uintptr_t end = begin + mapped;
  if (end > tail) munmap(reinterpret_cast<void*>(tail), end - tail);
  void* p = reinterpret_cast<void*>(aligned);
  MarkForHugePages(p, size);  // A hint: the mapping works either way.
  return p;
}

void AdviseHugePages(const void* begin, size_t bytes) {
  const uintptr_t first = AlignUp(reinterpret_cast<uintptr_t>(begin));
  const uintptr_t last = AlignDown(reinterpret_cast<uintptr_t>(begin) + bytes);
  if (last <= first) return;
  void* p = reinterpret_cast<void*>(first);
  if (!MarkForHugePages(p, last - first)) return;
  constexpr int kMadvCollapse = 25;  // MADV_COLLAPSE; Debian 12's headers predate it.
  madvise(p, last - first, kMadvCollapse);
}

void FreeHugePages(void* p, size_t bytes) { munmap(p, AlignUp(bytes)); }

}  // namespace neuralmesh
