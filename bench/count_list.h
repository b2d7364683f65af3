// Parsing of the comma-separated count lists that the benchmarks take as flags.
#ifndef NEURALMESH_BENCH_COUNT_LIST_H_
#define NEURALMESH_BENCH_COUNT_LIST_H_

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"
#include "absl/strings/string_view.h"

namespace neuralmesh::bench {

// "1000,5000" -> {1000, 5000}. On anything but positive integers, prints a message naming
// `program` and exits with status 2.
inline std::vector<size_t> ParseCountList(const std::string& text, const char* program) {
  std::vector<size_t> out;
  for (absl::string_view part : absl::StrSplit(text, ',', absl::SkipEmpty())) {
    size_t value = 0;
    if (!absl::SimpleAtoi(part, &value) || value == 0) {
      std::fprintf(stderr, "%s: '%s' is not a positive integer\n", program,
                   std::string(part).c_str());
      std::exit(2);
    }
    out.push_back(value);
  }
  return out;
}

}  // namespace neuralmesh::bench

#endif  // NEURALMESH_BENCH_COUNT_LIST_H_
