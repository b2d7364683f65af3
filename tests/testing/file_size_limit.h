// A file size limit (RLIMIT_FSIZE, as `ulimit -f` sets) for the scope of a test: writes past
// it fail with EFBIG, as a full disk fails them with ENOSPC. SIGXFSZ is ignored, as
// neuralmesh-server ignores it, so that the write fails instead of killing the process.
#ifndef NEURALMESH_TESTS_TESTING_FILE_SIZE_LIMIT_H_
#define NEURALMESH_TESTS_TESTING_FILE_SIZE_LIMIT_H_

#include <signal.h>
#include <sys/resource.h>

#include <cstdint>

#include "gtest/gtest.h"

namespace neuralmesh::testing {

class ScopedFileSizeLimit {
 public:
  explicit ScopedFileSizeLimit(uint64_t bytes) {
    signal(SIGXFSZ, SIG_IGN);
    EXPECT_EQ(getrlimit(RLIMIT_FSIZE, &old_), 0);
    rlimit limit = old_;
    limit.rlim_cur = bytes;
    EXPECT_EQ(setrlimit(RLIMIT_FSIZE, &limit), 0);
  }
  ~ScopedFileSizeLimit() { EXPECT_EQ(setrlimit(RLIMIT_FSIZE, &old_), 0); }

  ScopedFileSizeLimit(const ScopedFileSizeLimit&) = delete;
  ScopedFileSizeLimit& operator=(const ScopedFileSizeLimit&) = delete;

 private:
  rlimit old_{};
};

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_TESTING_FILE_SIZE_LIMIT_H_
