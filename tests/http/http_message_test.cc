#include "http/http_message.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

namespace neuralmesh::http {
namespace {

using ::testing::HasSubstr;

TEST(HttpMessageTest, ParsesARequestLineWithItsQueryAndHeaders) {
  const absl::StatusOr<HttpRequest> request = ParseHttpRequestHead(
      "GET /api/sessions/s-1%2F2/mesh?after=12&x=a+b%21&after=13 HTTP/1.1\r\n"
      "Host: 127.0.0.1:8080\r\n"
      "Accept:   */*  \r\n"
      "\r\n");
  ASSERT_TRUE(request.ok()) << request.status();
  EXPECT_EQ(request->method, "GET");
  EXPECT_EQ(request->path, "/api/sessions/s-1/2/mesh") << "percent escapes are decoded";
  EXPECT_EQ(request->query.at("after"), "13") << "the last of a repeated name counts";
  EXPECT_EQ(request->query.at("x"), "a b!") << "'+' is a space in a query";
  EXPECT_EQ(request->headers.at("host"), "127.0.0.1:8080") << "names are lower-cased";
  EXPECT_EQ(request->headers.at("accept"), "*/*") << "values are trimmed";
}

TEST(HttpMessageTest, AcceptsBareLineFeedsAndHttp10) {
  const absl::StatusOr<HttpRequest> request =
      ParseHttpRequestHead("HEAD /index.html#top HTTP/1.0\nUser-Agent: test\n");
  ASSERT_TRUE(request.ok()) << request.status();
  EXPECT_EQ(request->method, "HEAD");
  EXPECT_EQ(request->path, "/index.html") << "the fragment is not part of the path";
  EXPECT_TRUE(request->query.empty());
}

TEST(HttpMessageTest, RejectsMalformedHeadsWithMessagesThatSayWhatIsWrong) {
  struct Case {
    std::string head;
    std::string message;
  };
  const Case cases[] = {
      {"", "empty"},
      {"GET /\r\n", "malformed request line"},
      {"GET  / HTTP/1.1\r\n", "malformed request line"},
      {"G(T / HTTP/1.1\r\n", "malformed request method"},
      {"GET / HTTP/2.0\r\n", "unsupported protocol"},
      {"GET http://example.com/ HTTP/1.1\r\n", "not an absolute path"},
      {"GET /a%2 HTTP/1.1\r\n", "malformed percent escape"},
      {"GET /a%zz HTTP/1.1\r\n", "malformed percent escape"},
      {"GET /a%00b HTTP/1.1\r\n", "NUL byte"},
      {"GET /?q=%0 HTTP/1.1\r\n", "malformed percent escape"},
      {"GET / HTTP/1.1\r\nno colon here\r\n", "malformed header line"},
      {"GET / HTTP/1.1\r\n: empty name\r\n", "malformed header line"},
      {"GET / HTTP/1.1\r\nbad name: x\r\n", "malformed header name"},
      {"GET / HTTP/1.1\r\nContent-Length: 5\r\n", "body"},
      {"GET / HTTP/1.1\r\nContent-Length: x\r\n", "body"},
      {"GET / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n", "body"},
      {"GET /" + std::string(kMaxRequestHeadBytes, 'a') + " HTTP/1.1\r\n", "longer than"},
  };
  for (const Case& c : cases) {
    const absl::StatusOr<HttpRequest> request = ParseHttpRequestHead(c.head);
    ASSERT_FALSE(request.ok()) << c.head.substr(0, 60);
    EXPECT_EQ(request.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(request.status().message(), HasSubstr(c.message)) << c.head.substr(0, 60);
  }
}

TEST(HttpMessageTest, AcceptsAnEmptyBodyLength) {
  EXPECT_TRUE(ParseHttpRequestHead("GET / HTTP/1.1\r\nContent-Length: 0\r\n").ok());
}

TEST(HttpMessageTest, FindsTheEndOfTheHead) {
  EXPECT_EQ(FindEndOfHead("GET / HTTP/1.1\r\nHost: a\r\n"), 0u) << "not complete yet";
  EXPECT_EQ(FindEndOfHead("GET / HTTP/1.1\r\nHost: a\r\n\r\nrest"), 27u);
  EXPECT_EQ(FindEndOfHead("GET / HTTP/1.1\n\nrest"), 16u);
  EXPECT_EQ(FindEndOfHead(""), 0u);
}

TEST(HttpMessageTest, WritesTheResponseHeadWithTheBodyLength) {
  HttpResponse response = TextResponse(404, "no such page: /x");
  response.headers.emplace_back("X-Extra", "1");
  const std::string head = SerializeHttpResponseHead(response);
  EXPECT_THAT(head, ::testing::StartsWith("HTTP/1.1 404 Not Found\r\n"));
  EXPECT_THAT(head, HasSubstr("Content-Length: 17\r\n"));
  EXPECT_THAT(head, HasSubstr("Content-Type: text/plain; charset=utf-8\r\n"));
  EXPECT_THAT(head, HasSubstr("Cache-Control: no-store\r\n"));
  EXPECT_THAT(head, HasSubstr("Connection: close\r\n"));
  EXPECT_THAT(head, ::testing::EndsWith("X-Extra: 1\r\n\r\n"));
  EXPECT_EQ(JsonResponse(200, "[]").content_type, "application/json");
}

}  // namespace
}  // namespace neuralmesh::http
