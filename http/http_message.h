// The HTTP/1.1 messages of the live viewer (`neuralmesh view`) and of the server's metrics
// endpoint: a request head parsed from the bytes a browser or a scraper sends, and a response
// written back. Only what they need: GET and HEAD requests without a body, responses with a
// fixed Content-Length and "Connection: close".
#ifndef NEURALMESH_HTTP_HTTP_MESSAGE_H_
#define NEURALMESH_HTTP_HTTP_MESSAGE_H_

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace neuralmesh::http {

// A request head is at most this long (request line and headers); a longer one is refused.
inline constexpr size_t kMaxRequestHeadBytes = 16 * 1024;

struct HttpRequest {
  std::string method;                          // "GET", "HEAD", ... as sent (case-sensitive).
  std::string path;                            // Percent-decoded, starts with '/'.
  std::map<std::string, std::string> query;    // Percent-decoded; the last of repeated names.
  std::map<std::string, std::string> headers;  // Names lower-cased, values trimmed.
  // Set by HttpServer: the client sent a certificate that the TLS context's client CAs signed
  // (TlsServerContext::Create).
  bool client_certificate = false;
  // And that certificate's common name (empty without one).
  std::string client_common_name;
};

// Parses a request head: the request line and the header lines, each ending in CRLF (or LF),
// without the empty line that ends the head. INVALID_ARGUMENT, with a message that says what
// is wrong, for a malformed request line, an HTTP version other than 1.0 or 1.1, a target that
// is not an absolute path (or that decodes to a NUL byte, or holds a malformed percent escape),
// a malformed header line, or a request that announces a body (a viewer's requests have none).
absl::StatusOr<HttpRequest> ParseHttpRequestHead(absl::string_view head);

// Where the head ends in `bytes` received so far: the offset just past the empty line (CRLF
// CRLF or LF LF), or 0 when it has not arrived yet.
size_t FindEndOfHead(absl::string_view bytes);

struct HttpResponse {
  int status = 200;
  std::string content_type = "text/plain; charset=utf-8";
  std::string cache_control = "no-store";
  std::vector<std::pair<std::string, std::string>> headers;  // Besides the ones written always.
  std::string body;
};

// A response whose body is `message` and a line break, as plain text.
HttpResponse TextResponse(int status, absl::string_view message);

// A response whose body is the JSON document `json`.
HttpResponse JsonResponse(int status, std::string json);

// The reason phrase of a status code ("Not Found"); "Unknown" for codes not used here.
absl::string_view HttpReasonPhrase(int status);

// The response head: status line, Content-Type, Content-Length, Cache-Control,
// X-Content-Type-Options: nosniff, Connection: close, then `response.headers`, and the empty
// line. The body follows it unless the request was a HEAD.
std::string SerializeHttpResponseHead(const HttpResponse& response);

}  // namespace neuralmesh::http

#endif  // NEURALMESH_HTTP_HTTP_MESSAGE_H_
