// Metrics in the Prometheus text exposition format (version 0.0.4), the format Prometheus,
// VictoriaMetrics, Grafana Agent and OpenTelemetry collectors scrape:
//
//   # HELP neuralmesh_sessions Sessions held, by state.
//   # TYPE neuralmesh_sessions gauge
//   neuralmesh_sessions{state="learning"} 2
//
//   PrometheusText text;
//   text.Family("neuralmesh_sessions", "gauge", "Sessions held, by state.");
//   text.Sample("neuralmesh_sessions", {{"state", "learning"}}, 2);
//   ... text.str() ...
#ifndef NEURALMESH_SERVER_PROMETHEUS_TEXT_H_
#define NEURALMESH_SERVER_PROMETHEUS_TEXT_H_

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/string_view.h"

namespace neuralmesh::server {

// Label names and values, in the order written.
using MetricLabels = std::vector<std::pair<std::string, std::string>>;

// The content type of the format, for an HTTP response.
inline constexpr char kPrometheusTextContentType[] = "text/plain; version=0.0.4; charset=utf-8";

class PrometheusText {
 public:
  // Starts a family: its HELP and TYPE lines ("counter", "gauge" or "histogram"). Its samples
  // follow, each family once.
  void Family(absl::string_view name, absl::string_view type, absl::string_view help);

  // One sample line. `name` is the family's, or for a histogram its name with _bucket, _sum or
  // _count. Label values are escaped (backslash, double quote, line feed); a double is written
  // with the digits that give it back (+Inf, -Inf, NaN as such).
  void Sample(absl::string_view name, const MetricLabels& labels, uint64_t value);
  void Sample(absl::string_view name, const MetricLabels& labels, double value);

  // A family of one sample without labels.
  void Single(absl::string_view name, absl::string_view type, absl::string_view help,
              uint64_t value);
  void Single(absl::string_view name, absl::string_view type, absl::string_view help, double value);

  // A histogram's samples: for each upper bound in `bounds` (ascending) the count of
  // observations at most that (`counts[i]` observations fell in (bounds[i-1], bounds[i]],
  // counts[bounds.size()] above the last), then le="+Inf", _sum and _count.
  void Histogram(absl::string_view name, const MetricLabels& labels,
                 const std::vector<double>& bounds, const std::vector<uint64_t>& counts,
                 double sum);

  const std::string& str() const { return text_; }

 private:
  void SampleText(absl::string_view name, const MetricLabels& labels, absl::string_view value);

  std::string text_;
};

}  // namespace neuralmesh::server

#endif  // NEURALMESH_SERVER_PROMETHEUS_TEXT_H_
