// For tests of HTTP servers (the live viewer, the server's metrics): a raw HTTP/1.1 client that
// sends bytes to 127.0.0.1:PORT and reads the whole response (those servers close each
// connection after their answer).
#ifndef NEURALMESH_TESTS_TESTING_HTTP_CLIENT_H_
#define NEURALMESH_TESTS_TESTING_HTTP_CLIENT_H_

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <map>
#include <string>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"
#include "absl/strings/string_view.h"
#include "absl/strings/strip.h"

namespace neuralmesh::testing {

struct HttpReply {
  int status = 0;                              // 0 when no response came.
  std::map<std::string, std::string> headers;  // Names lower-cased.
  std::string body;

  // The header's value; empty when missing.
  std::string Header(const std::string& name) const {
    auto it = headers.find(name);
    return it == headers.end() ? "" : it->second;
  }
};

// A socket connected to 127.0.0.1:PORT; -1 when the connection fails.
inline int ConnectToLoopback(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    close(fd);
    return -1;
  }
  return fd;
}

// The response in `bytes`, all a server sent before it closed.
inline HttpReply ParseHttpReply(const std::string& bytes) {
  HttpReply reply;
  const size_t end = bytes.find("\r\n\r\n");
  if (end == std::string::npos) return reply;
  reply.body = bytes.substr(end + 4);
  bool first = true;
  for (absl::string_view line : absl::StrSplit(bytes.substr(0, end), "\r\n")) {
    if (first) {
      first = false;
      const std::vector<absl::string_view> parts = absl::StrSplit(line, ' ');
      if (parts.size() < 2 || !absl::SimpleAtoi(parts[1], &reply.status)) return reply;
      continue;
    }
    const size_t colon = line.find(':');
    if (colon == absl::string_view::npos) continue;
    reply.headers[absl::AsciiStrToLower(line.substr(0, colon))] =
        std::string(absl::StripAsciiWhitespace(line.substr(colon + 1)));
  }
  return reply;
}

// Sends `request` as is and reads until the server closes the connection.
inline HttpReply SendRawHttp(int port, const std::string& request) {
  const int fd = ConnectToLoopback(port);
  if (fd < 0) return HttpReply();
  send(fd, request.data(), request.size(), MSG_NOSIGNAL);
  std::string bytes;
  char buffer[65536];
  ssize_t got;
  while ((got = recv(fd, buffer, sizeof(buffer), 0)) > 0) bytes.append(buffer, got);
  close(fd);
  return ParseHttpReply(bytes);
}

inline HttpReply HttpGet(int port, const std::string& target) {
  return SendRawHttp(port, "GET " + target + " HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n");
}

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_TESTING_HTTP_CLIENT_H_
