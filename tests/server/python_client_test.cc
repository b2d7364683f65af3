// Runs tests/server/python_client_test.py (Debian's python3-grpcio, stubs generated from the
// .proto at test time) against a server on 127.0.0.1: the API works for other languages.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "absl/strings/str_cat.h"
#include "tests/server/server_test_support.h"

namespace neuralmesh::server {
namespace {

TEST(PythonClientTest, CompletesASessionAgainstTheProtoOnly) {
  // Debian's interpreter: it has python3-grpcio and python3-grpc-tools.
  if (std::system("/usr/bin/python3 -c 'import grpc, grpc_tools' 2> /dev/null") != 0) {
    FAIL() << "/usr/bin/python3 with python3-grpcio and python3-grpc-tools is required";
  }
  std::unique_ptr<ReconstructionServer> server = testing::StartServer(/*listen=*/true);
  ASSERT_NE(server, nullptr);
  // The working directory is the repository root.
  const std::string command =
      absl::StrCat("/usr/bin/python3 tests/server/python_client_test.py --target=",
                   server->target(), " --proto_root=proto");
  EXPECT_EQ(std::system(command.c_str()), 0) << "the Python client failed: " << command;
}

}  // namespace
}  // namespace neuralmesh::server
