// A pipe whose read end a stream under test reads (core/io/point_stream.h); what is written
// must fit in its buffer (64 KB), as nothing reads it meanwhile.
#ifndef NEURALMESH_TESTS_TESTING_PIPE_H_
#define NEURALMESH_TESTS_TESTING_PIPE_H_

#include <unistd.h>

#include "absl/strings/string_view.h"
#include "gtest/gtest.h"

namespace neuralmesh::testing {

class Pipe {
 public:
  Pipe() { EXPECT_EQ(pipe(fds_), 0); }
  ~Pipe() {
    CloseWriteEnd();
    close(fds_[0]);
  }
  Pipe(const Pipe&) = delete;
  Pipe& operator=(const Pipe&) = delete;

  int read_end() const { return fds_[0]; }
  void Write(absl::string_view bytes) {
    ASSERT_EQ(write(fds_[1], bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
  }
  void CloseWriteEnd() {
    if (fds_[1] >= 0) close(fds_[1]);
    fds_[1] = -1;
  }

 private:
  int fds_[2] = {-1, -1};
};

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_TESTING_PIPE_H_
