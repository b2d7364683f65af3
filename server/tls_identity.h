// The server's TLS identity (certificate chain, private key, client CAs), replaceable while the
// server runs: a renewed certificate applies to new connections without a restart, and the
// connections and sessions already running go on.
//
// gRPC's FileWatcherCertificateProvider re-reads a key and certificate pair from files every
// second, and takes whatever it finds: a key that is not the certificate's, or a half-written
// file, ends every handshake from then on. So the provider watches private copies (a directory
// of the process's own, mode 0700, removed with the identity), and Replace writes new copies
// there only after gRPC has accepted the new identity on a throw-away port, swapping a
// symbolic link so that the key and the certificate change together. A crash leaves the
// directory (neuralmesh-tls-* in the temporary directory), readable by the server's user only.
#ifndef NEURALMESH_SERVER_TLS_IDENTITY_H_
#define NEURALMESH_SERVER_TLS_IDENTITY_H_

#include <grpcpp/security/server_credentials.h>

#include <ctime>
#include <memory>
#include <string>
#include <utility>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"

namespace neuralmesh::server {

// PEM text (the contents of the files, not their paths). All empty: plaintext.
struct ServerTls {
  std::string certificate_chain;  // The server's certificate, then any intermediates.
  std::string private_key;        // The certificate's key.
  // Set: mutual TLS. Clients must present a certificate signed by one of these CAs, or the
  // handshake fails.
  std::string client_ca_certificates;

  bool enabled() const { return !certificate_chain.empty(); }
};

// Whether gRPC takes `tls` as a server identity: the parts are there and PEM, and a port on
// 127.0.0.1 binds with them (gRPC parses the certificate and the key, and checks that they
// belong together). INVALID_ARGUMENT saying what is wrong otherwise.
absl::Status CheckServerTls(const ServerTls& tls);

class ServerTlsIdentity {
 public:
  // CheckServerTls, then the copies and the provider watching them.
  static absl::StatusOr<std::unique_ptr<ServerTlsIdentity>> Create(const ServerTls& tls);
  ~ServerTlsIdentity();  // Removes the copies.

  ServerTlsIdentity(const ServerTlsIdentity&) = delete;
  ServerTlsIdentity& operator=(const ServerTlsIdentity&) = delete;

  // The credentials of a port that presents this identity, now and after each Replace. They
  // must not outlive the identity.
  const std::shared_ptr<grpc::ServerCredentials>& credentials() const { return credentials_; }

  // Makes `tls` the identity that handshakes present from about a second on (gRPC reads the
  // copies once a second). INVALID_ARGUMENT, the identity unchanged, when CheckServerTls
  // refuses it or it would turn mutual TLS on or off (that takes a restart); INTERNAL when the
  // copies cannot be written. Thread-safe.
  absl::Status Replace(const ServerTls& tls) ABSL_LOCKS_EXCLUDED(mu_);

 private:
  explicit ServerTlsIdentity(std::string directory, bool mutual)
      : directory_(std::move(directory)), mutual_(mutual) {}

  // Writes `tls` as version `version_ + 1` and points the watched link at it.
  absl::Status Publish(const ServerTls& tls) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);

  const std::string directory_;
  const bool mutual_;
  std::shared_ptr<grpc::ServerCredentials> credentials_;
  absl::Mutex mu_;
  int version_ ABSL_GUARDED_BY(mu_) = 0;
  time_t mtime_ ABSL_GUARDED_BY(mu_) = 0;  // The modification time of the last version's files.
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_TLS_IDENTITY_H_
