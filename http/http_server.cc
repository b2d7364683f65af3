#include "http/http_server.h"

#include <netdb.h>
#include <pthread.h>
#include <signal.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>
#include <utility>

#include "absl/strings/str_cat.h"
#include "http/server_connection.h"

namespace neuralmesh::http {
namespace {

// How long a write may wait for the client to take more of a response.
constexpr absl::Duration kWriteTimeout = absl::Seconds(30);

void Respond(ServerConnection& connection, const HttpResponse& response, bool with_body) {
  if (connection.SendAll(SerializeHttpResponseHead(response)) && with_body) {
    connection.SendAll(response.body);
  }
}

// Reads until the end of the request head. NOT_FOUND when the peer closed or timed out before
// sending one, RESOURCE_EXHAUSTED when the head is too long.
absl::StatusOr<std::string> ReadRequestHead(ServerConnection& connection) {
  std::string bytes;
  char buffer[4096];
  while (true) {
    const size_t got = connection.Receive(buffer, sizeof(buffer));
    if (got == 0) return absl::NotFoundError("no request");
    bytes.append(buffer, got);
    const size_t end = FindEndOfHead(bytes);
    if (end != 0 && end <= kMaxRequestHeadBytes) {
      bytes.resize(end);
      return bytes;
    }
    if (bytes.size() > kMaxRequestHeadBytes) {
      return absl::ResourceExhaustedError(
          absl::StrCat("the request head is longer than ", kMaxRequestHeadBytes, " bytes"));
    }
  }
}

// SSL_write writes with write(2), which raises SIGPIPE when the client has gone; in this
// connection's thread the signal stays pending instead, and is dropped when the thread ends.
void BlockSigpipeInThisThread() {
  sigset_t pipe;
  sigemptyset(&pipe);
  sigaddset(&pipe, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe, nullptr);
}

}  // namespace

absl::StatusOr<std::unique_ptr<HttpServer>> HttpServer::Start(const std::string& host, int port,
                                                              HttpHandler handler,
                                                              const HttpServerOptions& options) {
  if (port < 0 || port > 65535) {
    return absl::InvalidArgumentError(absl::StrCat("port ", port, " is not in [0, 65535]"));
  }
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  if (const int error =
          getaddrinfo(host.empty() ? nullptr : host.c_str(), service.c_str(), &hints, &found);
      error != 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("cannot resolve host \"", host, "\": ", gai_strerror(error)));
  }
  std::string last_error = "no address";
  int fd = -1;
  for (addrinfo* a = found; a != nullptr && fd < 0; a = a->ai_next) {
    fd = socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) {
      last_error = std::strerror(errno);
      continue;
    }
    const int yes = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
    if (bind(fd, a->ai_addr, a->ai_addrlen) != 0 || listen(fd, 64) != 0) {
      last_error = std::strerror(errno);
      close(fd);
      fd = -1;
    }
  }
  freeaddrinfo(found);
  if (fd < 0) {
    return absl::UnavailableError(
        absl::StrCat("cannot listen on ", host, ":", port, ": ", last_error));
  }
  sockaddr_storage bound{};
  socklen_t length = sizeof(bound);
  getsockname(fd, reinterpret_cast<sockaddr*>(&bound), &length);
  const int bound_port =
      ntohs(bound.ss_family == AF_INET6 ? reinterpret_cast<sockaddr_in6*>(&bound)->sin6_port
                                        : reinterpret_cast<sockaddr_in*>(&bound)->sin_port);
  const int wake = eventfd(0, EFD_CLOEXEC);
  if (wake < 0) {
    close(fd);
    return absl::InternalError(absl::StrCat("eventfd: ", std::strerror(errno)));
  }
  auto server = std::unique_ptr<HttpServer>(
      new HttpServer(fd, wake, bound_port, std::move(handler), options));
  {
    absl::MutexLock lock(&server->mu_);
    server->tls_ = options.tls;
  }
  server->accept_thread_ = std::thread([s = server.get()] { s->AcceptLoop(); });
  return server;
}

HttpServer::HttpServer(int listen_fd, int wake_fd, int port, HttpHandler handler,
                       const HttpServerOptions& options)
    : listen_fd_(listen_fd),
      wake_fd_(wake_fd),
      port_(port),
      speaks_tls_(options.tls != nullptr),
      handler_(std::move(handler)),
      options_(options) {}

HttpServer::~HttpServer() {
  Shutdown();
  close(wake_fd_);
}

absl::Status HttpServer::ReplaceTls(std::shared_ptr<const TlsServerContext> tls) {
  if (!speaks_tls_) {
    return absl::FailedPreconditionError("this HTTP server was started without TLS");
  }
  if (tls == nullptr) return absl::InvalidArgumentError("no TLS context to replace with");
  absl::MutexLock lock(&mu_);
  tls_ = std::move(tls);
  return absl::OkStatus();
}

void HttpServer::Shutdown() {
  {
    absl::MutexLock lock(&mu_);
    if (shut_down_) return;
    shut_down_ = true;
    for (int fd : open_fds_) shutdown(fd, SHUT_RDWR);
  }
  const uint64_t one = 1;
  (void)!write(wake_fd_, &one, sizeof(one));
  accept_thread_.join();
  close(listen_fd_);
  absl::MutexLock lock(&mu_);
  mu_.Await(absl::Condition(
      +[](std::set<int>* fds) { return fds->empty(); }, &open_fds_));
}

void HttpServer::AcceptLoop() {
  while (true) {
    pollfd fds[2] = {{listen_fd_, POLLIN, 0}, {wake_fd_, POLLIN, 0}};
    if (poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      return;
    }
    if (fds[1].revents != 0) return;
    const int fd = accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (fd < 0) continue;  // The peer gave up, or descriptors ran out: the next one may work.
    const absl::Time read_deadline = absl::Now() + options_.read_timeout;
    {
      absl::MutexLock lock(&mu_);
      if (shut_down_) {
        close(fd);
        return;
      }
      if (static_cast<int>(open_fds_.size()) >= options_.max_connections) {
        if (!speaks_tls_) {  // A TLS client could not read the answer before a handshake.
          ServerConnection connection(fd, read_deadline, kWriteTimeout);
          Respond(connection,
                  TextResponse(503, absl::StrCat("this server serves at most ",
                                                 options_.max_connections,
                                                 " connections at once: try again")),
                  true);
        }
        close(fd);
        continue;
      }
      open_fds_.insert(fd);
    }
    try {
      std::thread([this, fd, read_deadline] { Serve(fd, read_deadline); }).detach();
    } catch (const std::system_error&) {  // No thread to be had: refuse this one.
      if (!speaks_tls_) {
        ServerConnection connection(fd, read_deadline, kWriteTimeout);
        Respond(connection, TextResponse(503, "this server cannot start a thread: try again"),
                true);
      }
      absl::MutexLock lock(&mu_);
      open_fds_.erase(fd);
      close(fd);
    }
  }
}

void HttpServer::Serve(int fd, absl::Time read_deadline) {
  BlockSigpipeInThisThread();
  std::shared_ptr<const TlsServerContext> tls;
  {
    absl::MutexLock lock(&mu_);
    tls = tls_;
  }
  ServerConnection connection(fd, read_deadline, kWriteTimeout);
  // Under TLS a request in plain HTTP is still read and answered, in plain HTTP, so that a
  // browser or scraper pointed at http:// learns why.
  const bool plain_on_tls = tls != nullptr && !connection.StartsWithTlsHandshake();
  if (tls == nullptr || plain_on_tls || connection.AcceptTls(*tls).ok()) {
    absl::StatusOr<std::string> head = ReadRequestHead(connection);
    if (head.ok() && plain_on_tls) {
      Respond(connection,
              TextResponse(400, "this port speaks HTTPS only: use an https:// address"), true);
    } else if (head.ok()) {
      absl::StatusOr<HttpRequest> request = ParseHttpRequestHead(*head);
      if (!request.ok()) {
        Respond(connection, TextResponse(400, request.status().message()), true);
      } else if (request->method != "GET" && request->method != "HEAD") {
        HttpResponse response = TextResponse(
            405, absl::StrCat("method ", request->method, " is not allowed: use GET or HEAD"));
        response.headers.emplace_back("Allow", "GET, HEAD");
        Respond(connection, response, true);
      } else {
        request->client_certificate = connection.client_certificate_verified();
        if (request->client_certificate) {
          request->client_common_name = connection.client_common_name();
        }
        Respond(connection, handler_(*request), request->method == "GET");
      }
    } else if (absl::IsResourceExhausted(head.status())) {
      Respond(connection, TextResponse(431, head.status().message()), true);
    }
    connection.EndSending(absl::Seconds(1));
  }
  absl::MutexLock lock(&mu_);
  open_fds_.erase(fd);
  close(fd);
}

}  // namespace neuralmesh::http
