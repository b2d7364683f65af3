#include "server/prometheus_text.h"

#include <gtest/gtest.h>

#include <limits>

namespace neuralmesh::server {
namespace {

TEST(PrometheusTextTest, FamilyLinesThenSamplesWithTheirLabels) {
  PrometheusText text;
  text.Family("jobs_total", "counter", "Jobs done.");
  text.Sample("jobs_total", {}, uint64_t{18446744073709551615u});
  text.Sample("jobs_total", {{"kind", "a"}, {"code", "OK"}}, uint64_t{3});
  EXPECT_EQ(text.str(),
            "# HELP jobs_total Jobs done.\n"
            "# TYPE jobs_total counter\n"
            "jobs_total 18446744073709551615\n"
            "jobs_total{kind=\"a\",code=\"OK\"} 3\n");
}

TEST(PrometheusTextTest, EscapesLabelValuesAndHelp) {
  PrometheusText text;
  text.Family("x", "gauge", "a \\ b\nc");
  text.Sample("x", {{"v", "q\"u\\o\nte"}}, uint64_t{1});
  EXPECT_EQ(text.str(),
            "# HELP x a \\\\ b\\nc\n"
            "# TYPE x gauge\n"
            "x{v=\"q\\\"u\\\\o\\nte\"} 1\n");
}

TEST(PrometheusTextTest, DoublesInTheShortestDigitsThatReadBack) {
  PrometheusText text;
  text.Sample("a", {}, 0.1);
  text.Sample("b", {}, 0.0025);
  text.Sample("c", {}, 1.0 / 3.0);
  text.Sample("d", {}, std::numeric_limits<double>::infinity());
  text.Sample("e", {}, -std::numeric_limits<double>::infinity());
  text.Sample("f", {}, std::numeric_limits<double>::quiet_NaN());
  text.Sample("g", {}, 1796487481.9402781);
  EXPECT_EQ(text.str(),
            "a 0.1\nb 0.0025\nc 0.3333333333333333\nd +Inf\ne -Inf\nf NaN\n"
            "g 1796487481.940278\n");
}

TEST(PrometheusTextTest, HistogramBucketsAreCumulative) {
  PrometheusText text;
  text.Histogram("t_seconds", {{"m", "Get"}}, {0.5, 1}, {2, 0, 3}, 7.25);
  EXPECT_EQ(text.str(),
            "t_seconds_bucket{m=\"Get\",le=\"0.5\"} 2\n"
            "t_seconds_bucket{m=\"Get\",le=\"1\"} 2\n"
            "t_seconds_bucket{m=\"Get\",le=\"+Inf\"} 5\n"
            "t_seconds_sum{m=\"Get\"} 7.25\n"
            "t_seconds_count{m=\"Get\"} 5\n");
}

}  // namespace
}  // namespace neuralmesh::server
