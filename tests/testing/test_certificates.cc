#include "tests/testing/test_certificates.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/io/file_contents.h"

namespace neuralmesh::testing {
namespace {

absl::Status Run(const std::string& dir, const std::string& command) {
  const std::string log = dir + "/openssl.log";
  const std::string line = absl::StrCat("cd '", dir, "' && (", command, ") > '", log, "' 2>&1");
  if (std::system(line.c_str()) == 0) return absl::OkStatus();
  std::ifstream in(log);
  std::stringstream output;
  output << in.rdbuf();
  return absl::InternalError(absl::StrCat("'", command, "' failed:\n", output.str()));
}

// A CA named `name` (name.pem, name.key).
std::string MakeCa(const std::string& name) {
  return absl::StrCat(
      "openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -days 2 "
      "-subj /CN=neuralmesh-test-",
      name, " -keyout ", name, ".key -out ", name, ".pem");
}

// A certificate `name` (name.pem, name.key) signed by `ca`, with the subjectAltName `san`.
std::string MakeSigned(const std::string& name, const std::string& ca, const std::string& san) {
  return absl::StrCat(
      "openssl req -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -subj "
      "/CN=neuralmesh-test-",
      name, " -keyout ", name, ".key -out ", name, ".csr && printf 'subjectAltName=", san,
      "\\n' > ", name, ".ext && openssl x509 -req -in ", name, ".csr -CA ", ca, ".pem -CAkey ",
      ca, ".key -CAcreateserial -days 2 -extfile ", name, ".ext -out ", name, ".pem");
}

}  // namespace

absl::StatusOr<TestCertificates> MakeTestCertificates(const std::string& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) return absl::InternalError(absl::StrCat("cannot create ", dir, ": ", error.message()));
  for (const std::string& step :
       {MakeCa("ca"), MakeCa("other_ca"),
        MakeSigned("server", "ca", "IP:127.0.0.1,DNS:localhost"),
        MakeSigned("named_server", "ca", "DNS:scans.example.test"),
        MakeSigned("client", "ca", "DNS:neuralmesh-test-client"),
        MakeSigned("second_client", "ca", "DNS:neuralmesh-test-second_client"),
        MakeSigned("other_client", "other_ca", "DNS:neuralmesh-test-client")}) {
    if (absl::Status s = Run(dir, step); !s.ok()) return s;
  }
  TestCertificates certificates;
  certificates.dir = dir;
  const std::pair<std::string*, const char*> files[] = {
      {&certificates.ca, "ca.pem"},
      {&certificates.server_chain, "server.pem"},
      {&certificates.server_key, "server.key"},
      {&certificates.client_chain, "client.pem"},
      {&certificates.client_key, "client.key"},
      {&certificates.second_client_chain, "second_client.pem"},
      {&certificates.second_client_key, "second_client.key"},
      {&certificates.other_ca, "other_ca.pem"},
      {&certificates.other_client_chain, "other_client.pem"},
      {&certificates.other_client_key, "other_client.key"},
      {&certificates.named_server_chain, "named_server.pem"},
      {&certificates.named_server_key, "named_server.key"}};
  for (const auto& [text, file] : files) {
    absl::StatusOr<std::string> read = ReadFileContents(certificates.Path(file));
    if (!read.ok()) return read.status();
    *text = *std::move(read);
  }
  return certificates;
}

}  // namespace neuralmesh::testing
