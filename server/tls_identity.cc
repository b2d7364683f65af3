#include "server/tls_identity.h"

#include <fcntl.h>
#include <grpcpp/security/tls_certificate_provider.h>
#include <grpcpp/security/tls_credentials_options.h>
#include <grpcpp/server.h>
#include <grpcpp/server_builder.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <ctime>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"

namespace neuralmesh::server {
namespace {

// How often gRPC reads the copies again, in seconds (its smallest step).
constexpr unsigned kRefreshSeconds = 1;
constexpr char kKeyFile[] = "key.pem";
constexpr char kCertificateFile[] = "certificate.pem";
constexpr char kClientCaFile[] = "client_ca.pem";
constexpr char kCurrentLink[] = "current";

absl::Status CheckPem(const std::string& pem, const char* what) {
  if (absl::StrContains(pem, "-----BEGIN ")) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat("the TLS ", what, " is not PEM text (no '-----BEGIN ' line)"));
}

absl::Status ErrnoError(const std::string& what) {
  return absl::InternalError(absl::StrCat(what, ": ", std::strerror(errno)));
}

// Writes `contents` to a new file readable by this user only, modified at `mtime`.
absl::Status WritePrivateFile(const std::string& path, const std::string& contents,
                              time_t mtime) {
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) return ErrnoError(absl::StrCat("cannot create ", path));
  size_t written = 0;
  while (written < contents.size()) {
    const ssize_t n = write(fd, contents.data() + written, contents.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      close(fd);
      return ErrnoError(absl::StrCat("cannot write ", path));
    }
    written += static_cast<size_t>(n);
  }
  const timespec times[2] = {{mtime, 0}, {mtime, 0}};
  if (futimens(fd, times) != 0) {
    close(fd);
    return ErrnoError(absl::StrCat("cannot set the time of ", path));
  }
  if (close(fd) != 0) return ErrnoError(absl::StrCat("cannot write ", path));
  return absl::OkStatus();
}

}  // namespace

absl::Status CheckServerTls(const ServerTls& tls) {
  if (tls.certificate_chain.empty()) {
    return absl::InvalidArgumentError("no TLS server certificate was given");
  }
  if (tls.private_key.empty()) {
    return absl::InvalidArgumentError("the TLS certificate was given without its private key");
  }
  if (absl::Status s = CheckPem(tls.certificate_chain, "certificate"); !s.ok()) return s;
  if (absl::Status s = CheckPem(tls.private_key, "private key"); !s.ok()) return s;
  grpc::SslServerCredentialsOptions options;
  options.pem_key_cert_pairs.push_back({tls.private_key, tls.certificate_chain});
  if (!tls.client_ca_certificates.empty()) {
    if (absl::Status s = CheckPem(tls.client_ca_certificates, "client CA"); !s.ok()) return s;
    options.pem_root_certs = tls.client_ca_certificates;
    options.client_certificate_request =
        GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY;
  }
  // gRPC parses the certificate and the key, and matches them, when it binds a port.
  int port = 0;
  grpc::ServerBuilder builder;
  builder.AddListeningPort("127.0.0.1:0", grpc::SslServerCredentials(options), &port);
  std::unique_ptr<grpc::Server> trial = builder.BuildAndStart();
  const bool accepted = trial != nullptr && port != 0;
  if (trial != nullptr) trial->Shutdown();
  if (!accepted) {
    return absl::InvalidArgumentError(
        "gRPC rejected the TLS certificate or key: are both PEM, and is the key the "
        "certificate's?");
  }
  return absl::OkStatus();
}

absl::StatusOr<std::unique_ptr<ServerTlsIdentity>> ServerTlsIdentity::Create(
    const ServerTls& tls) {
  if (absl::Status s = CheckServerTls(tls); !s.ok()) return s;
  std::error_code error;
  const std::filesystem::path temp = std::filesystem::temp_directory_path(error);
  if (error) return absl::InternalError(absl::StrCat("no temporary directory: ", error.message()));
  std::string pattern = (temp / "neuralmesh-tls-XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) {  // Mode 0700.
    return ErrnoError(absl::StrCat("cannot create a directory for the TLS identity in ",
                                   temp.string()));
  }
  const bool mutual = !tls.client_ca_certificates.empty();
  std::unique_ptr<ServerTlsIdentity> identity(new ServerTlsIdentity(pattern, mutual));
  {
    absl::MutexLock lock(&identity->mu_);
    if (absl::Status s = identity->Publish(tls); !s.ok()) return s;
  }
  const std::string current = absl::StrCat(pattern, "/", kCurrentLink, "/");
  auto provider = std::make_shared<grpc::experimental::FileWatcherCertificateProvider>(
      current + kKeyFile, current + kCertificateFile, mutual ? current + kClientCaFile : "",
      kRefreshSeconds);
  grpc::experimental::TlsServerCredentialsOptions options(provider);
  options.watch_identity_key_cert_pairs();
  if (mutual) {
    options.watch_root_certs();
    options.set_cert_request_type(GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY);
  }
  identity->credentials_ = grpc::experimental::TlsServerCredentials(options);
  return identity;
}

ServerTlsIdentity::~ServerTlsIdentity() {
  credentials_.reset();  // The provider stops reading, unless a port still holds it.
  std::error_code ignored;
  std::filesystem::remove_all(directory_, ignored);
}

absl::Status ServerTlsIdentity::Replace(const ServerTls& tls) {
  if (!tls.client_ca_certificates.empty() != mutual_) {
    return absl::InvalidArgumentError(
        mutual_ ? "the server runs mutual TLS: a new identity needs client CAs too (turning "
                  "mutual TLS off takes a restart)"
                : "the server runs TLS without client certificates: turning mutual TLS on "
                  "takes a restart");
  }
  if (absl::Status s = CheckServerTls(tls); !s.ok()) return s;
  absl::MutexLock lock(&mu_);
  return Publish(tls);
}

absl::Status ServerTlsIdentity::Publish(const ServerTls& tls) {
  const int next = version_ + 1;
  const std::string version = absl::StrCat("v", next);
  const std::string dir = absl::StrCat(directory_, "/", version);
  if (mkdir(dir.c_str(), 0700) != 0) return ErrnoError(absl::StrCat("cannot create ", dir));
  // gRPC reads the key and the certificate through the link one after the other, and reads
  // them again when their modification times (in seconds) changed meanwhile. Each version's
  // files carry a later second than the last one's, so that a swap between the two reads
  // always shows.
  const time_t mtime = std::max(time(nullptr), mtime_ + 1);
  if (absl::Status s =
          WritePrivateFile(absl::StrCat(dir, "/", kKeyFile), tls.private_key, mtime);
      !s.ok()) {
    return s;
  }
  if (absl::Status s = WritePrivateFile(absl::StrCat(dir, "/", kCertificateFile),
                                        tls.certificate_chain, mtime);
      !s.ok()) {
    return s;
  }
  if (mutual_) {
    if (absl::Status s = WritePrivateFile(absl::StrCat(dir, "/", kClientCaFile),
                                          tls.client_ca_certificates, mtime);
        !s.ok()) {
      return s;
    }
  }
  // One rename moves the key and the certificate together.
  const std::string link = absl::StrCat(directory_, "/", kCurrentLink);
  const std::string new_link = link + ".new";
  unlink(new_link.c_str());
  if (symlink(version.c_str(), new_link.c_str()) != 0) {
    return ErrnoError(absl::StrCat("cannot link ", new_link));
  }
  if (rename(new_link.c_str(), link.c_str()) != 0) {
    return ErrnoError(absl::StrCat("cannot replace ", link));
  }
  // The version before the previous one: a read that began before the last swap is over.
  if (next > 2) {
    std::error_code ignored;
    std::filesystem::remove_all(absl::StrCat(directory_, "/v", next - 2), ignored);
  }
  version_ = next;
  mtime_ = mtime;
  return absl::OkStatus();
}

}  // namespace neuralmesh::server
