#include "client/reload_signal.h"

#include <atomic>

namespace neuralmesh::client {
namespace {

std::atomic<bool> reload_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler needs a lock-free flag");

extern "C" void OnReloadSignal(int) { reload_requested.store(true); }

}  // namespace

ReloadSignalScope::ReloadSignalScope() {
  reload_requested.store(false);
  struct sigaction action = {};
  action.sa_handler = OnReloadSignal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGHUP, &action, &previous_);
}

ReloadSignalScope::~ReloadSignalScope() { sigaction(SIGHUP, &previous_, nullptr); }

bool ReloadSignalScope::TakeRequest() { return reload_requested.exchange(false); }

}  // namespace neuralmesh::client
