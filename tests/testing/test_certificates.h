// Throw-away TLS material for tests, made with the openssl command-line tool: a CA, a server
// certificate it signs for 127.0.0.1 and localhost, one it signs for a name only, a client
// certificate it signs, and a second CA that signs nothing the server trusts. Valid for two
// days from now.
#ifndef NEURALMESH_TESTS_TESTING_TEST_CERTIFICATES_H_
#define NEURALMESH_TESTS_TESTING_TEST_CERTIFICATES_H_

#include <string>

#include "absl/status/statusor.h"

namespace neuralmesh::testing {

// PEM text, and the files it was read from (for command-line tests).
struct TestCertificates {
  std::string dir;
  std::string ca;                         // ca.pem: the CA that signs the others.
  std::string server_chain, server_key;   // server.pem, server.key: for 127.0.0.1, localhost.
  // client.pem, client.key: signed by the CA, common name neuralmesh-test-client.
  std::string client_chain, client_key;
  // second_client.pem, .key: signed by the CA, common name neuralmesh-test-second_client.
  std::string second_client_chain, second_client_key;
  std::string other_ca;                   // other_ca.pem: an unrelated CA.
  std::string other_client_chain, other_client_key;  // other_client.*: signed by other_ca.
  // named_server.pem, .key: signed by the CA for the name scans.example.test only.
  std::string named_server_chain, named_server_key;

  std::string Path(const std::string& file) const { return dir + "/" + file; }
};

// Writes the files into `dir` (created if missing) and reads them back. INTERNAL with
// openssl's output when a step fails (is the openssl package installed?).
absl::StatusOr<TestCertificates> MakeTestCertificates(const std::string& dir);

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_TESTING_TEST_CERTIFICATES_H_
