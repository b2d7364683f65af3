#include "core/huge_page_allocator.h"

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

constexpr uintptr_t kHugePage = uintptr_t{2} << 20;

// The VmFlags line of the mapping of /proc/self/smaps that contains `p`, or "" if none does.
std::string VmFlagsOfMappingAt(const void* p) {
  std::ifstream smaps("/proc/self/smaps");
  const uintptr_t address = reinterpret_cast<uintptr_t>(p);
  bool inside = false;
  std::string line;
  while (std::getline(smaps, line)) {
    uintptr_t begin = 0, end = 0;
    char dash = 0;
    std::istringstream header(line);
    if (header >> std::hex >> begin >> dash >> end && dash == '-') {
      inside = begin <= address && address < end;
    } else if (inside && line.rfind("VmFlags:", 0) == 0) {
      return line;
    }
  }
  return "";
}

bool KernelHasTransparentHugePages() {
  return std::ifstream("/sys/kernel/mm/transparent_hugepage/enabled").good();
}

TEST(HugePageAllocatorTest, LargeArraysAreAlignedToHugePagesAndMarkedForThem) {
  HugePageVector<Vec3f> points(kHugePageMinBytes / sizeof(Vec3f) + 1000);
  EXPECT_EQ(reinterpret_cast<uintptr_t>(points.data()) % kHugePage, 0u)
      << "an array of 1 MB or more starts on a 2 MB boundary";
  if (KernelHasTransparentHugePages()) {
    EXPECT_NE(VmFlagsOfMappingAt(points.data()).find(" hg"), std::string::npos)
        << "the mapping is marked MADV_HUGEPAGE: " << VmFlagsOfMappingAt(points.data());
  }
  for (size_t i = 0; i < points.size(); ++i) points[i] = Vec3f(i, -1.0f * i, 0.5f);
  EXPECT_EQ(points.back(), Vec3f(points.size() - 1, 1.0f - points.size(), 0.5f))
      << "the whole array is writable";
}

TEST(HugePageAllocatorTest, SmallArraysComeFromTheHeapUnmarked) {
  HugePageVector<double> small(100, 1.5);
  EXPECT_EQ(reinterpret_cast<uintptr_t>(small.data()) % alignof(double), 0u);
  if (KernelHasTransparentHugePages()) {
    EXPECT_EQ(VmFlagsOfMappingAt(small.data()).find(" hg"), std::string::npos)
        << "a small array must not mark the heap it lives in: " << VmFlagsOfMappingAt(small.data());
  }
}

TEST(HugePageAllocatorTest, GrowingAcrossTheThresholdKeepsTheContents) {
  HugePageVector<int> values;
  const int n = static_cast<int>(3 * kHugePageMinBytes / sizeof(int));
  for (int i = 0; i < n; ++i) values.push_back(i * 7);
  for (int i = 0; i < n; i += 997) ASSERT_EQ(values[i], i * 7) << "element " << i;
  EXPECT_EQ(values.back(), (n - 1) * 7);
  values.resize(10);
  values.shrink_to_fit();  // Back from a mapping to the heap.
  EXPECT_EQ(values[9], 63);
}

TEST(HugePageAllocatorTest, AdvisingAnArrayAllocatedElsewhereKeepsItsContents) {
  std::vector<float> values(3 * kHugePage / sizeof(float));
  for (size_t i = 0; i < values.size(); ++i) values[i] = static_cast<float>(i % 100003);
  AdviseHugePages(values.data(), values.size() * sizeof(float));
  for (size_t i = 0; i < values.size(); i += 4099) {
    ASSERT_EQ(values[i], static_cast<float>(i % 100003)) << "element " << i;
  }
  const uintptr_t interior =
      (reinterpret_cast<uintptr_t>(values.data()) + kHugePage - 1) & ~(kHugePage - 1);
  if (KernelHasTransparentHugePages()) {
    const std::string flags = VmFlagsOfMappingAt(reinterpret_cast<const void*>(interior));
    EXPECT_NE(flags.find(" hg"), std::string::npos)
        << "the whole 2 MB pages inside the array are marked MADV_HUGEPAGE: " << flags;
  }
  AdviseHugePages(values.data(), 1000);  // No whole huge page inside: nothing to do.
  EXPECT_EQ(values[999 / sizeof(float)], static_cast<float>(999 / sizeof(float)));
}

}  // namespace
}  // namespace neuralmesh
