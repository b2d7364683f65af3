// The live viewer's reading of the bytes a browser (or anyone who can reach the viewer's port)
// sends: http/http_message.h. Properties:
//  - FindEndOfHead returns 0 or an offset just past an empty line within the input;
//  - ParseHttpRequestHead never crashes, and either rejects the head with INVALID_ARGUMENT
//    and a message, or returns a method of token characters, a path that starts with '/' and
//    holds no NUL byte, and lower-case header names;
//  - a head longer than kMaxRequestHeadBytes is always rejected.
#include <cstddef>
#include <cstdint>
#include <string>

#include "absl/strings/ascii.h"
#include "absl/strings/string_view.h"
#include "fuzz/fuzz_check.h"
#include "http/http_message.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using neuralmesh::http::FindEndOfHead;
  using neuralmesh::http::HttpRequest;
  using neuralmesh::http::kMaxRequestHeadBytes;
  using neuralmesh::http::ParseHttpRequestHead;
  const absl::string_view bytes(reinterpret_cast<const char*>(data), size);

  const size_t end = FindEndOfHead(bytes);
  FUZZ_CHECK(end <= size, "end of head %zu past %zu bytes", end, size);
  if (end != 0) {
    const absl::string_view head = bytes.substr(0, end);
    FUZZ_CHECK(head.substr(head.size() - 2) == "\n\n" || head.substr(head.size() - 3) == "\n\r\n",
               "end of head %zu is not after an empty line", end);
  }

  const absl::StatusOr<HttpRequest> request = ParseHttpRequestHead(bytes);
  if (!request.ok()) {
    FUZZ_CHECK(request.status().code() == absl::StatusCode::kInvalidArgument &&
                   !request.status().message().empty(),
               "rejected with %s", request.status().ToString().c_str());
    return 0;
  }
  FUZZ_CHECK(size <= kMaxRequestHeadBytes, "a head of %zu bytes was accepted", size);
  FUZZ_CHECK(!request->method.empty(), "empty method accepted");
  for (char c : request->method) {
    FUZZ_CHECK(c > ' ' && c < 127 && c != '(' && c != ')' && c != '/' && c != ':',
               "method character %d accepted", c);
  }
  FUZZ_CHECK(!request->path.empty() && request->path[0] == '/', "path \"%s\" is not absolute",
             request->path.c_str());
  FUZZ_CHECK(request->path.find('\0') == std::string::npos, "path holds a NUL byte");
  for (const auto& [name, value] : request->headers) {
    FUZZ_CHECK(!name.empty() && absl::AsciiStrToLower(name) == name,
               "header name \"%s\" is not lower-case", name.c_str());
  }
  return 0;
}
