// Huge pages for the learner's large arrays. HugePageAllocator, a standard allocator for the
// arrays indexed by vertex (octree, ring cache, signal counters): an allocation of
// kHugePageMinBytes or more gets a mapping of its own, aligned to 2 MB and marked for transparent
// huge pages (madvise MADV_HUGEPAGE); smaller ones come from operator new.
//
// Why: a Basic Step reads these arrays, and the input points, at random places, so on a large
// mesh or input each of those loads can also miss the TLB, and on a virtual machine a page walk
// costs about as much as the load itself. Measured with scripts/ab-bench.sh on 5M points: the
// learner's arrays on huge pages took 1-2% off the time per step from 20K to 100K vertices; the
// input points (AdviseHugePages, from the point-cloud samplers) 16% below 1K vertices, 8% to
// 5K and 3% above. Only these ranges are marked, not the process's heap: in the server, other
// sessions and every thread's stack keep 4 KB pages. Where the kernel has no transparent huge
// pages (or has them set to "never"), the madvise fails quietly and nothing changes.
#ifndef NEURALMESH_CORE_HUGE_PAGE_ALLOCATOR_H_
#define NEURALMESH_CORE_HUGE_PAGE_ALLOCATOR_H_

#include <cstddef>
#include <new>
#include <vector>

namespace neuralmesh {

// Below this, an allocation comes from operator new (rounding it up to a huge page would
// waste more than half of it).
inline constexpr size_t kHugePageMinBytes = size_t{1} << 20;

// Maps `bytes` (at least kHugePageMinBytes) aligned to 2 MB, rounded up to whole 2 MB pages,
// and asks for huge pages. Throws std::bad_alloc when the mapping fails.
void* AllocateHugePages(size_t bytes);
// Unmaps what AllocateHugePages(bytes) returned, with the same `bytes`.
void FreeHugePages(void* p, size_t bytes);

template <typename T>
class HugePageAllocator {
 public:
  using value_type = T;

  HugePageAllocator() = default;
  template <typename U>
  HugePageAllocator(const HugePageAllocator<U>&) {}  // NOLINT: allocators convert implicitly.

  T* allocate(size_t n) {
    const size_t bytes = n * sizeof(T);
    if (bytes >= kHugePageMinBytes) return static_cast<T*>(AllocateHugePages(bytes));
    return static_cast<T*>(::operator new (bytes, std::align_val_t{alignof(T)}));
  }
  void deallocate(T* p, size_t n) {
    const size_t bytes = n * sizeof(T);
    if (bytes >= kHugePageMinBytes) {
      FreeHugePages(p, bytes);
    } else {
      ::operator delete (p, std::align_val_t{alignof(T)});
    }
  }

  friend bool operator==(const HugePageAllocator&, const HugePageAllocator&) { return true; }
  friend bool operator!=(const HugePageAllocator&, const HugePageAllocator&) { return false; }
};

template <typename T>
using HugePageVector = std::vector<T, HugePageAllocator<T>>;

// For a large array allocated elsewhere (a point cloud's positions): asks for huge pages
// under the whole 2 MB pages inside [begin, begin + bytes), and has the kernel move the array
// onto them now (MADV_COLLAPSE, Linux 6.1 and later; before, they come as the kernel gets to
// it). Contents stay as they are; without transparent huge pages nothing happens. It costs
// about what touching the range for the first time does.
void AdviseHugePages(const void* begin, size_t bytes);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_HUGE_PAGE_ALLOCATOR_H_
