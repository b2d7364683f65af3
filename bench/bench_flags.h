// Flag parsing shared by the benchmarks: `--help` lists the flags of the benchmark's own source
// file (absl's default looks for a file named like the program, and the programs are named with
// dashes where the files have underscores) under the usage line the file's header gives.
#ifndef NEURALMESH_BENCH_BENCH_FLAGS_H_
#define NEURALMESH_BENCH_BENCH_FLAGS_H_

#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/flags/usage_config.h"
#include "absl/strings/match.h"
#include "absl/strings/string_view.h"

namespace neuralmesh {

// Call first thing in main. `usage`: what the program does and its command line.
inline void ParseBenchFlags(int argc, char** argv, absl::string_view usage) {
  absl::FlagsUsageConfig config;
  config.contains_help_flags = [](absl::string_view file) {
    return absl::StrContains(file, "bench/");
  };
  config.contains_helpshort_flags = config.contains_help_flags;
  absl::SetFlagsUsageConfig(config);
  absl::SetProgramUsageMessage(usage);
  absl::ParseCommandLine(argc, argv);
}

}  // namespace neuralmesh

#endif  // NEURALMESH_BENCH_BENCH_FLAGS_H_
