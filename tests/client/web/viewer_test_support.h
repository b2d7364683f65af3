// For the viewer's tests: the wait for a `neuralmesh view` process to say where it listens, and
// (tests/testing/http_client.h) a raw HTTP client to ask it.
#ifndef NEURALMESH_TESTS_CLIENT_WEB_VIEWER_TEST_SUPPORT_H_
#define NEURALMESH_TESTS_CLIENT_WEB_VIEWER_TEST_SUPPORT_H_

#include <regex>
#include <string>

#include "absl/time/clock.h"
#include "tests/client/subprocess.h"
#include "tests/testing/http_client.h"

namespace neuralmesh::testing {

// The port of `viewer` (neuralmesh view --listen=127.0.0.1:0) once it prints its URL with
// `scheme`, or 0 when it exits or says nothing within 10 s.
inline int WaitForViewerPort(BackgroundProcess& viewer, const std::string& scheme = "http") {
  const std::regex line("viewer: " + scheme + "://127\\.0\\.0\\.1:([0-9]+)/ \\(sessions of ");
  for (int i = 0; i < 200; ++i) {
    std::smatch match;
    const std::string out = viewer.Stdout();
    if (std::regex_search(out, match, line)) return std::stoi(match[1].str());
    if (!viewer.Running()) return 0;
    absl::SleepFor(absl::Milliseconds(50));
  }
  return 0;
}

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_CLIENT_WEB_VIEWER_TEST_SUPPORT_H_
