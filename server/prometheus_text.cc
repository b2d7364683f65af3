#include "server/prometheus_text.h"

#include <cmath>
#include <cstdlib>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace neuralmesh::server {
namespace {

// Backslashes and line feeds escaped, and with `quotes` double quotes (label values; HELP
// text keeps its quotes).
std::string Escape(absl::string_view text, bool quotes) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    if (c == '\\') {
      out += "\\\\";
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '"' && quotes) {
      out += "\\\"";
    } else {
      out += c;
    }
  }
  return out;
}

std::string FormatDouble(double value) {
  if (std::isnan(value)) return "NaN";
  if (std::isinf(value)) return value > 0 ? "+Inf" : "-Inf";
  // The shortest of 15 to 17 significant digits that reads back as the same double.
  std::string text;
  for (int digits = 15; digits <= 17; ++digits) {
    text = absl::StrFormat("%.*g", digits, value);
    if (std::strtod(text.c_str(), nullptr) == value) break;
  }
  return text;
}

}  // namespace

void PrometheusText::Family(absl::string_view name, absl::string_view type,
                            absl::string_view help) {
  absl::StrAppend(&text_, "# HELP ", name, " ", Escape(help, /*quotes=*/false), "\n# TYPE ", name,
                  " ", type, "\n");
}

void PrometheusText::Sample(absl::string_view name, const MetricLabels& labels, uint64_t value) {
  SampleText(name, labels, absl::StrCat(value));
}

void PrometheusText::Sample(absl::string_view name, const MetricLabels& labels, double value) {
  SampleText(name, labels, FormatDouble(value));
}

void PrometheusText::Single(absl::string_view name, absl::string_view type, absl::string_view help,
                            uint64_t value) {
  Family(name, type, help);
  Sample(name, {}, value);
}

void PrometheusText::Single(absl::string_view name, absl::string_view type, absl::string_view help,
                            double value) {
  Family(name, type, help);
  Sample(name, {}, value);
}

void PrometheusText::Histogram(absl::string_view name, const MetricLabels& labels,
                               const std::vector<double>& bounds,
                               const std::vector<uint64_t>& counts, double sum) {
  const std::string bucket = absl::StrCat(name, "_bucket");
  uint64_t cumulative = 0;
  for (size_t i = 0; i <= bounds.size(); ++i) {
    cumulative += i < counts.size() ? counts[i] : 0;
    MetricLabels with_bound = labels;
    with_bound.emplace_back("le", i < bounds.size() ? FormatDouble(bounds[i]) : "+Inf");
    Sample(bucket, with_bound, cumulative);
  }
  Sample(absl::StrCat(name, "_sum"), labels, sum);
  Sample(absl::StrCat(name, "_count"), labels, cumulative);
}

void PrometheusText::SampleText(absl::string_view name, const MetricLabels& labels,
                                absl::string_view value) {
  absl::StrAppend(&text_, name);
  if (!labels.empty()) {
    text_ += '{';
    for (size_t i = 0; i < labels.size(); ++i) {
      absl::StrAppend(&text_, i > 0 ? "," : "", labels[i].first, "=\"",
                      Escape(labels[i].second, /*quotes=*/true), "\"");
    }
    text_ += '}';
  }
  absl::StrAppend(&text_, " ", value, "\n");
}

}  // namespace neuralmesh::server
