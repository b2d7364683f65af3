#include "http/http_message.h"

#include <cctype>

#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace neuralmesh::http {
namespace {

int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Percent-decodes `text`; in a query, '+' stands for a space.
absl::StatusOr<std::string> PercentDecode(absl::string_view text, bool plus_is_space) {
  std::string decoded;
  decoded.reserve(text.size());
  for (size_t i = 0; i < text.size(); ++i) {
    char c = text[i];
    if (c == '%') {
      const int high = i + 2 < text.size() ? HexValue(text[i + 1]) : -1;
      const int low = i + 2 < text.size() ? HexValue(text[i + 2]) : -1;
      if (high < 0 || low < 0) {
        return absl::InvalidArgumentError(
            absl::StrCat("malformed percent escape in \"", text, "\""));
      }
      c = static_cast<char>(high * 16 + low);
      i += 2;
    } else if (c == '+' && plus_is_space) {
      c = ' ';
    }
    if (c == '\0') {
      return absl::InvalidArgumentError(absl::StrCat("\"", text, "\" decodes to a NUL byte"));
    }
    decoded.push_back(c);
  }
  return decoded;
}

bool IsTokenChar(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 ||
         absl::string_view("!#$%&'*+-.^_`|~").find(c) != absl::string_view::npos;
}

absl::Status ParseTarget(absl::string_view target, HttpRequest& request) {
  if (target.empty() || target[0] != '/') {
    return absl::InvalidArgumentError(
        absl::StrCat("the request target \"", target, "\" is not an absolute path"));
  }
  const size_t fragment = target.find('#');
  if (fragment != absl::string_view::npos) target = target.substr(0, fragment);
  const size_t question = target.find('?');
  absl::StatusOr<std::string> path = PercentDecode(target.substr(0, question), false);
  if (!path.ok()) return path.status();
  request.path = *std::move(path);
  if (question == absl::string_view::npos) return absl::OkStatus();
  for (absl::string_view pair :
       absl::StrSplit(target.substr(question + 1), '&', absl::SkipEmpty())) {
    const std::pair<absl::string_view, absl::string_view> name_value =
        absl::StrSplit(pair, absl::MaxSplits('=', 1));
    absl::StatusOr<std::string> name = PercentDecode(name_value.first, true);
    if (!name.ok()) return name.status();
    absl::StatusOr<std::string> value = PercentDecode(name_value.second, true);
    if (!value.ok()) return value.status();
    request.query[*std::move(name)] = *std::move(value);
  }
  return absl::OkStatus();
}

}  // namespace

size_t FindEndOfHead(absl::string_view bytes) {
  for (size_t i = 0; i < bytes.size(); ++i) {
    if (bytes[i] != '\n') continue;
    if (i + 1 < bytes.size() && bytes[i + 1] == '\n') return i + 2;
    if (i + 2 < bytes.size() && bytes[i + 1] == '\r' && bytes[i + 2] == '\n') return i + 3;
  }
  return 0;
}

absl::StatusOr<HttpRequest> ParseHttpRequestHead(absl::string_view head) {
  if (head.size() > kMaxRequestHeadBytes) {
    return absl::InvalidArgumentError(
        absl::StrCat("the request head is longer than ", kMaxRequestHeadBytes, " bytes"));
  }
  std::vector<absl::string_view> lines = absl::StrSplit(head, '\n');
  for (absl::string_view& line : lines) absl::ConsumeSuffix(&line, "\r");
  while (!lines.empty() && lines.back().empty()) lines.pop_back();
  if (lines.empty()) return absl::InvalidArgumentError("the request is empty");

  const std::vector<absl::string_view> parts = absl::StrSplit(lines[0], ' ');
  if (parts.size() != 3 || parts[0].empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("malformed request line \"", lines[0], "\": expected METHOD TARGET HTTP/1.1"));
  }
  HttpRequest request;
  for (char c : parts[0]) {
    if (!IsTokenChar(c)) {
      return absl::InvalidArgumentError(
          absl::StrCat("malformed request method \"", parts[0], "\""));
    }
  }
  request.method = std::string(parts[0]);
  if (parts[2] != "HTTP/1.1" && parts[2] != "HTTP/1.0") {
    return absl::InvalidArgumentError(
        absl::StrCat("unsupported protocol \"", parts[2], "\": expected HTTP/1.1 or HTTP/1.0"));
  }
  if (absl::Status target = ParseTarget(parts[1], request); !target.ok()) return target;

  for (size_t i = 1; i < lines.size(); ++i) {
    const absl::string_view line = lines[i];
    const size_t colon = line.find(':');
    if (colon == 0 || colon == absl::string_view::npos) {
      return absl::InvalidArgumentError(absl::StrCat("malformed header line \"", line, "\""));
    }
    const absl::string_view name = line.substr(0, colon);
    for (char c : name) {
      if (!IsTokenChar(c)) {
        return absl::InvalidArgumentError(absl::StrCat("malformed header name \"", name, "\""));
      }
    }
    request.headers[absl::AsciiStrToLower(name)] =
        std::string(absl::StripAsciiWhitespace(line.substr(colon + 1)));
  }
  if (request.headers.count("transfer-encoding") != 0) {
    return absl::InvalidArgumentError("requests with a body are not accepted");
  }
  if (auto length = request.headers.find("content-length"); length != request.headers.end()) {
    uint64_t bytes = 0;
    if (!absl::SimpleAtoi(length->second, &bytes) || bytes != 0) {
      return absl::InvalidArgumentError("requests with a body are not accepted");
    }
  }
  return request;
}

HttpResponse TextResponse(int status, absl::string_view message) {
  HttpResponse response;
  response.status = status;
  response.body = absl::StrCat(message, "\n");
  return response;
}

HttpResponse JsonResponse(int status, std::string json) {
  HttpResponse response;
  response.status = status;
  response.content_type = "application/json";
  response.body = std::move(json);
  return response;
}

absl::string_view HttpReasonPhrase(int status) {
  switch (status) {
    case 200:
      return "OK";
    case 204:
      return "No Content";
    case 303:
      return "See Other";
    case 400:
      return "Bad Request";
    case 401:
      return "Unauthorized";
    case 404:
      return "Not Found";
    case 405:
      return "Method Not Allowed";
    case 410:
      return "Gone";
    case 431:
      return "Request Header Fields Too Large";
    case 500:
      return "Internal Server Error";
    case 502:
      return "Bad Gateway";
    case 503:
      return "Service Unavailable";
    case 504:
      return "Gateway Timeout";
    default:
      return "Unknown";
  }
}

std::string SerializeHttpResponseHead(const HttpResponse& response) {
  std::string head =
      absl::StrCat("HTTP/1.1 ", response.status, " ", HttpReasonPhrase(response.status), "\r\n");
  absl::StrAppend(&head, "Content-Type: ", response.content_type, "\r\n");
  absl::StrAppend(&head, "Content-Length: ", response.body.size(), "\r\n");
  absl::StrAppend(&head, "Cache-Control: ", response.cache_control, "\r\n");
  absl::StrAppend(&head, "X-Content-Type-Options: nosniff\r\n");
  absl::StrAppend(&head, "Connection: close\r\n");
  for (const auto& [name, value] : response.headers) {
    absl::StrAppend(&head, name, ": ", value, "\r\n");
  }
  absl::StrAppend(&head, "\r\n");
  return head;
}

}  // namespace neuralmesh::http
