// Ctrl-C as a request rather than an abrupt end: while an InterruptScope lives, the first
// SIGINT or SIGTERM only sets a flag that long-running commands poll, so they can stop at a
// consistent point (write the mesh learned so far, cancel their server session); a second one
// ends the process at once.
#ifndef NEURALMESH_CLIENT_INTERRUPT_H_
#define NEURALMESH_CLIENT_INTERRUPT_H_

#include <csignal>

namespace neuralmesh::client {

class InterruptScope {
 public:
  // Installs the handlers; the destructor restores the previous ones. Scopes do not nest.
  InterruptScope();
  ~InterruptScope();
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;

  // Whether SIGINT or SIGTERM arrived since the scope began. Async-signal-safe.
  static bool interrupted();

 private:
  struct sigaction previous_int_;
  struct sigaction previous_term_;
};

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_INTERRUPT_H_
