#include "server/event_log.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "tests/server/server_test_support.h"

namespace neuralmesh::server {
namespace {

TEST(EventLogTest, EachLineStartsWithTheUtcTimeAndNamesTheSession) {
  testing::CapturedEvents events;
  EventLog log(events.Sink());
  log.Record("s-0123456789abcdef", "created by ipv4:127.0.0.1:5000: \"scan\"");
  ASSERT_EQ(events.lines().size(), 1u);
  EXPECT_TRUE(std::regex_match(
      events.lines()[0],
      std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z session s-0123456789abcdef )"
                 R"(created by ipv4:127\.0\.0\.1:5000: "scan")")))
      << events.lines()[0];
}

TEST(EventLogTest, ANullSinkRecordsNothingAndLinesFromManyThreadsStayWhole) {
  EventLog quiet(nullptr);
  quiet.Record("s-1", "created");  // Nothing to check but that it does not crash.

  testing::CapturedEvents events;
  EventLog log(events.Sink());
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&log, t] {
      for (int i = 0; i < 200; ++i) log.Record(absl::StrCat("s-", t), absl::StrCat("event ", i));
    });
  }
  for (std::thread& thread : threads) thread.join();
  const std::vector<std::string> lines = events.lines();
  ASSERT_EQ(lines.size(), 800u);
  for (const std::string& line : lines) {
    EXPECT_TRUE(std::regex_search(line, std::regex(R"(Z session s-\d event \d+$)"))) << line;
  }
}

}  // namespace
}  // namespace neuralmesh::server
