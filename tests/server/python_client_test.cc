// Runs tests/server/python_client_test.py (Debian's python3-grpcio, stubs generated from the
// .proto at test time) against a server on 127.0.0.1: the API works for other languages.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <string>

#include "absl/strings/str_cat.h"
#include "tests/server/server_test_support.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_certificates.h"

namespace neuralmesh::server {
namespace {

// Runs the Python client against `server` with `extra_args`.
void RunPythonClient(const ReconstructionServer& server, const std::string& extra_args) {
  // Debian's interpreter: it has python3-grpcio and python3-grpc-tools.
  if (std::system("/usr/bin/python3 -c 'import grpc, grpc_tools' 2> /dev/null") != 0) {
    FAIL() << "/usr/bin/python3 with python3-grpcio and python3-grpc-tools is required";
  }
  // The working directory is the repository root.
  const std::string command =
      absl::StrCat("/usr/bin/python3 tests/server/python_client_test.py --target=",
                   server.target(), " --proto_root=proto", extra_args);
  EXPECT_EQ(std::system(command.c_str()), 0) << "the Python client failed: " << command;
}

TEST(PythonClientTest, CompletesASessionAgainstTheProtoOnly) {
  std::unique_ptr<ReconstructionServer> server = testing::StartServer(/*listen=*/true);
  ASSERT_NE(server, nullptr);
  RunPythonClient(*server, "");
}

TEST(PythonClientTest, CompletesASessionOverTlsWithAnAccessToken) {
  absl::StatusOr<neuralmesh::testing::TestCertificates> certificates =
      neuralmesh::testing::MakeTestCertificates(
          neuralmesh::testing::MakeTempDir("tls"));
  ASSERT_TRUE(certificates.ok()) << certificates.status();
  constexpr char kToken[] = "python-token-0123456789";
  ServerOptions options;
  options.security.tls.certificate_chain = certificates->server_chain;
  options.security.tls.private_key = certificates->server_key;
  options.security.access_tokens = {kToken};
  std::unique_ptr<ReconstructionServer> server = testing::StartServer(/*listen=*/true, options);
  ASSERT_NE(server, nullptr);
  RunPythonClient(*server, absl::StrCat(" --root_cert=", certificates->Path("ca.pem"),
                                        " --token=", kToken));
}

}  // namespace
}  // namespace neuralmesh::server
