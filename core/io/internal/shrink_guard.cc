#include "core/io/internal/shrink_guard.h"

#include <signal.h>
#include <sys/mman.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <mutex>

namespace neuralmesh::io_internal {
namespace {

// A guarded range; begin == 0 marks a free slot. The handler reads these without a lock: a
// slot is filled (end, then begin) before its range is read and emptied before it is unmapped.
struct GuardedRange {
  std::atomic<uintptr_t> begin{0};
  std::atomic<uintptr_t> end{0};
  std::atomic<bool> cut_short{false};
};

GuardedRange g_ranges[kMaxGuardedRanges];
std::mutex g_slots_mutex;  // Taken to fill and empty slots, never by the handler.
struct sigaction g_previous_action;
uintptr_t g_page_size = 4096;

// A SIGBUS outside the guarded ranges goes where it would have gone without the guard.
void PassOn(int signal, siginfo_t* info, void* context) {
  if ((g_previous_action.sa_flags & SA_SIGINFO) != 0) {
    if (g_previous_action.sa_sigaction != nullptr) {
      g_previous_action.sa_sigaction(signal, info, context);
      return;
    }
  } else if (g_previous_action.sa_handler != SIG_DFL && g_previous_action.sa_handler != SIG_IGN) {
    g_previous_action.sa_handler(signal);
    return;
  }
  // The default action: the faulting read runs again when this returns and, with the default
  // action back in place, kills the process as it would have.
  struct sigaction default_action = {};
  default_action.sa_handler = SIG_DFL;
  sigemptyset(&default_action.sa_mask);
  sigaction(SIGBUS, &default_action, nullptr);
}

void OnSigbus(int signal, siginfo_t* info, void* context) {
  const int saved_errno = errno;
  const uintptr_t address = reinterpret_cast<uintptr_t>(info->si_addr);
  if (info->si_code == BUS_ADRERR) {
    for (GuardedRange& range : g_ranges) {
      const uintptr_t begin = range.begin.load(std::memory_order_acquire);
      if (begin == 0 || address < begin) continue;
      const uintptr_t end = range.end.load(std::memory_order_acquire);
      if (address >= end) continue;
      // Every page from the faulting one on lies past the file's end: zeros over all of them,
      // so that the read goes on and later ones do not fault again.
      const uintptr_t page = address & ~(g_page_size - 1);
      void* zeros = mmap(reinterpret_cast<void*>(page), end - page, PROT_READ,
                         MAP_PRIVATE | MAP_ANONYMOUS | MAP_FIXED, -1, 0);
      if (zeros == MAP_FAILED) break;
      range.cut_short.store(true, std::memory_order_release);
      errno = saved_errno;
      return;
    }
  }
  errno = saved_errno;
  PassOn(signal, info, context);
}

void InstallHandler() {
  g_page_size = static_cast<uintptr_t>(sysconf(_SC_PAGESIZE));
  struct sigaction action = {};
  action.sa_sigaction = OnSigbus;
  action.sa_flags = SA_SIGINFO | SA_ONSTACK;
  sigemptyset(&action.sa_mask);
  sigaction(SIGBUS, &action, &g_previous_action);
}

}  // namespace

int GuardRange(const char* begin, size_t size) {
  static std::once_flag installed;
  std::call_once(installed, InstallHandler);
  std::lock_guard<std::mutex> lock(g_slots_mutex);
  for (int slot = 0; slot < kMaxGuardedRanges; ++slot) {
    GuardedRange& range = g_ranges[slot];
    if (range.begin.load(std::memory_order_relaxed) != 0) continue;
    range.cut_short.store(false, std::memory_order_relaxed);
    range.end.store(reinterpret_cast<uintptr_t>(begin) + size, std::memory_order_relaxed);
    range.begin.store(reinterpret_cast<uintptr_t>(begin), std::memory_order_release);
    return slot;
  }
  return -1;
}

void ReleaseRange(int slot) {
  if (slot < 0) return;
  std::lock_guard<std::mutex> lock(g_slots_mutex);
  g_ranges[slot].begin.store(0, std::memory_order_release);
}

bool RangeCutShort(int slot) {
  return slot >= 0 && g_ranges[slot].cut_short.load(std::memory_order_acquire);
}

}  // namespace neuralmesh::io_internal
