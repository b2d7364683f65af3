// SIGHUP as a request to read files again (a renewed certificate), as daemons take it: while a
// ReloadSignalScope lives, each SIGHUP sets a flag that a long-running command polls and clears.
#ifndef NEURALMESH_CLIENT_RELOAD_SIGNAL_H_
#define NEURALMESH_CLIENT_RELOAD_SIGNAL_H_

#include <csignal>

namespace neuralmesh::client {

class ReloadSignalScope {
 public:
  // Installs the handler; the destructor restores the previous one. Scopes do not nest.
  ReloadSignalScope();
  ~ReloadSignalScope();
  ReloadSignalScope(const ReloadSignalScope&) = delete;
  ReloadSignalScope& operator=(const ReloadSignalScope&) = delete;

  // Whether SIGHUP arrived since the scope began or the last call, which clears it (several
  // signals in between count once).
  static bool TakeRequest();

 private:
  struct sigaction previous_;
};

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_RELOAD_SIGNAL_H_
