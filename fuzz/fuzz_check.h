// FUZZ_CHECK: the assertion of the fuzz targets. A property that fails prints where and why and
// aborts, which libFuzzer (and the corpus replay) reports as a crash with the input saved.
#ifndef NEURALMESH_FUZZ_FUZZ_CHECK_H_
#define NEURALMESH_FUZZ_FUZZ_CHECK_H_

#include <cstdio>
#include <cstdlib>

#define FUZZ_CHECK(condition, ...)                                                   \
  do {                                                                               \
    if (!(condition)) {                                                              \
      std::fprintf(stderr, "%s:%d: FUZZ_CHECK(%s) failed: ", __FILE__, __LINE__,     \
                   #condition);                                                      \
      std::fprintf(stderr, __VA_ARGS__);                                             \
      std::fprintf(stderr, "\n");                                                    \
      std::abort();                                                                  \
    }                                                                                \
  } while (false)

#endif  // NEURALMESH_FUZZ_FUZZ_CHECK_H_
