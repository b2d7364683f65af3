// How fast fresh memory can be written for the first time: each new page costs a page fault,
// and on a virtual machine the host may have to back the page too. Printed by service-bench
// before its ingest measurement: a session stores 12 bytes of fresh memory per point it takes
// (GrowingPointCloud's chunks), so on a machine whose page faults are slow this, not the
// network or the server's code, bounds the ingest rate.
#ifndef NEURALMESH_BENCH_FIRST_TOUCH_H_
#define NEURALMESH_BENCH_FIRST_TOUCH_H_

#include <sys/mman.h>
#include <unistd.h>

#include <chrono>
#include <cstddef>

namespace neuralmesh::bench {

// Bytes per second at which `bytes` of freshly mapped anonymous memory (4 KB pages, no
// huge-page advice, as the server's point chunks) are written once, one byte per page; 0 if
// the memory cannot be mapped.
inline double FirstTouchBytesPerSecond(size_t bytes) {
  void* mapped =
      mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (mapped == MAP_FAILED) return 0;
  volatile char* memory = static_cast<volatile char*>(mapped);
  const size_t page = static_cast<size_t>(sysconf(_SC_PAGESIZE));
  const auto start = std::chrono::steady_clock::now();
  for (size_t at = 0; at < bytes; at += page) memory[at] = 1;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  munmap(mapped, bytes);
  return seconds > 0 ? static_cast<double>(bytes) / seconds : 0;
}

}  // namespace neuralmesh::bench

#endif  // NEURALMESH_BENCH_FIRST_TOUCH_H_
