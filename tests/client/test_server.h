// A real neuralmesh-server on 127.0.0.1, started as a subprocess for the client's tests.
#ifndef NEURALMESH_TESTS_CLIENT_TEST_SERVER_H_
#define NEURALMESH_TESTS_CLIENT_TEST_SERVER_H_

#include <unistd.h>

#include <filesystem>
#include <memory>
#include <regex>
#include <string>
#include <vector>

#include "tests/client/subprocess.h"

namespace neuralmesh::testing {

class TestServer {
 public:
  // Starts build/bin/neuralmesh-server with --port 0 (plus `extra_args`) and waits up to 20 s
  // for the line that names its port. Returns null (and `error` says why) on failure.
  static std::unique_ptr<TestServer> Start(const std::vector<std::string>& extra_args,
                                           std::string* error) {
    const std::string binary = BinDir() + "/neuralmesh-server";
    if (!std::filesystem::exists(binary)) {
      *error = binary + " does not exist: build it first (cmake --build build)";
      return nullptr;
    }
    std::vector<std::string> args = {"--host=127.0.0.1", "--port=0"};
    args.insert(args.end(), extra_args.begin(), extra_args.end());
    auto server = std::unique_ptr<TestServer>(new TestServer(args));
    const std::regex listening("listening on ([^ ]+):([0-9]+)");
    for (int i = 0; i < 400; ++i) {
      std::smatch match;
      const std::string out = server->process_.Stdout();
      if (std::regex_search(out, match, listening)) {
        server->address_ = "127.0.0.1:" + match[2].str();
        return server;
      }
      if (!server->process_.Running()) break;
      usleep(50 * 1000);
    }
    *error = "neuralmesh-server did not start; stderr:\n" + server->process_.Stderr();
    return nullptr;
  }

  const std::string& address() const { return address_; }
  std::string Stdout() const { return process_.Stdout(); }
  std::string Stderr() const { return process_.Stderr(); }
  // Wait up to 5 s for the server's standard output (error) to hold `text`; whether it came.
  bool AwaitStdout(const std::string& text) const { return process_.AwaitStdout(text); }
  bool AwaitStderr(const std::string& text) const { return process_.AwaitStderr(text); }
  // Sends `signal` to the server process (SIGSTOP: it stops answering, connections stay open).
  void Signal(int signal) { process_.Signal(signal); }

 private:
  explicit TestServer(const std::vector<std::string>& args) : process_("neuralmesh-server", args) {}

  BackgroundProcess process_;
  std::string address_;
};

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_CLIENT_TEST_SERVER_H_
