// A TCP proxy on 127.0.0.1 for tests of lost connections: it forwards each connection to a
// port of 127.0.0.1 and, once the clients have sent a given number of bytes through it, closes
// every connection open at that moment, once (later connections pass untouched). A test can
// also cut the connections itself (CutNow) and make the server look gone (SetRefusing: new
// connections are closed as soon as they are accepted).
#ifndef NEURALMESH_TESTS_CLIENT_TCP_PROXY_H_
#define NEURALMESH_TESTS_CLIENT_TCP_PROXY_H_

#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cstddef>
#include <limits>
#include <memory>
#include <thread>
#include <vector>

#include "absl/synchronization/mutex.h"

namespace neuralmesh::testing {

class TcpProxy {
 public:
  explicit TcpProxy(int target_port,
                    size_t cut_after_client_bytes = std::numeric_limits<size_t>::max())
      : target_port_(target_port), cut_after_(cut_after_client_bytes) {
    listener_ = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in address = Loopback(0);
    bind(listener_, reinterpret_cast<sockaddr*>(&address), sizeof(address));
    listen(listener_, 16);
    socklen_t length = sizeof(address);
    getsockname(listener_, reinterpret_cast<sockaddr*>(&address), &length);
    port_ = ntohs(address.sin_port);
    acceptor_ = std::thread([this] { Accept(); });
  }
  ~TcpProxy() {
    stopping_ = true;
    shutdown(listener_, SHUT_RDWR);
    close(listener_);
    acceptor_.join();
    CloseAll();
    for (std::thread& t : pumps_) t.join();
    for (int fd : open_) close(fd);
  }
  TcpProxy(const TcpProxy&) = delete;
  TcpProxy& operator=(const TcpProxy&) = delete;

  int port() const { return port_; }
  bool cut() const { return cut_done_; }
  // Closes every connection open now (later ones pass, unless refused).
  void CutNow() {
    cut_done_ = true;
    CloseAll();
  }
  void SetRefusing(bool refusing) { refusing_ = refusing; }

 private:
  static sockaddr_in Loopback(int port) {
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<uint16_t>(port));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    return address;
  }

  void Accept() {
    while (!stopping_) {
      const int client = accept(listener_, nullptr, nullptr);
      if (client < 0) return;
      if (refusing_) {
        close(client);
        continue;
      }
      const int server = socket(AF_INET, SOCK_STREAM, 0);
      sockaddr_in target = Loopback(target_port_);
      if (connect(server, reinterpret_cast<sockaddr*>(&target), sizeof(target)) != 0) {
        close(client);
        close(server);
        continue;
      }
      absl::MutexLock lock(&mu_);
      open_.push_back(client);
      open_.push_back(server);
      pumps_.emplace_back([this, client, server] { Pump(client, server); });
    }
  }

  // Copies bytes both ways until either side closes or the cut comes.
  void Pump(int client, int server) {
    char buffer[1 << 16];
    pollfd fds[2] = {{client, POLLIN, 0}, {server, POLLIN, 0}};
    while (poll(fds, 2, 100) >= 0 && !stopping_) {
      bool ended = false;
      for (int i = 0; i < 2; ++i) {
        if ((fds[i].revents & (POLLIN | POLLHUP | POLLERR)) == 0) continue;
        const ssize_t got = read(fds[i].fd, buffer, sizeof(buffer));
        if (got <= 0 || send(fds[1 - i].fd, buffer, got, MSG_NOSIGNAL) != got) {
          ended = true;
          break;
        }
        if (i == 0 && (client_bytes_ += got) >= cut_after_ && !cut_done_.exchange(true)) {
          CloseAll();
          return;
        }
      }
      if (ended) break;
    }
    shutdown(client, SHUT_RDWR);
    shutdown(server, SHUT_RDWR);
  }

  // Ends every connection open now: both sockets of each are shut down.
  void CloseAll() {
    absl::MutexLock lock(&mu_);
    for (int fd : open_) shutdown(fd, SHUT_RDWR);
  }

  const int target_port_;
  const size_t cut_after_;
  int listener_ = -1;
  int port_ = 0;
  std::atomic<bool> stopping_{false};
  std::atomic<size_t> client_bytes_{0};
  std::atomic<bool> cut_done_{false};
  std::atomic<bool> refusing_{false};
  std::thread acceptor_;
  absl::Mutex mu_;
  std::vector<int> open_;  // Never closed before the destructor (no fd reuse meanwhile).
  std::vector<std::thread> pumps_;
};

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_CLIENT_TCP_PROXY_H_
