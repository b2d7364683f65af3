// ByteSink: a string or a file written piece by piece, with bytes already written patched in
// place; a file sink opens its file at the first byte, removes what it failed to write in full,
// and writes to pipes and devices as well as to regular files.
#include "core/io/byte_sink.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>

#include "absl/strings/str_cat.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io/io_test_util.h"

namespace neuralmesh {
namespace {

using io_test::ReadBytes;
using io_test::TempPath;
using io_test::WriteBytes;
using ::testing::HasSubstr;

TEST(ByteSinkTest, AppendsFollowOneAnotherAndPatchesOverwriteInPlace) {
  StringSink text;
  ASSERT_TRUE(text.Append("header:????;").ok());
  ASSERT_TRUE(text.Append(std::string("body\0", 5)).ok());
  ASSERT_TRUE(text.Patch(7, "1234").ok());
  EXPECT_EQ(text.size(), 17u);
  EXPECT_EQ(text.bytes(), std::string("header:1234;body\0", 17));

  const std::string path = TempPath("sink.bin");
  WriteBytes(path, std::string(100, 'x'));  // Replaced, not overwritten.
  FileSink file(path);
  ASSERT_TRUE(file.Append("header:????;").ok());
  ASSERT_TRUE(file.Append(std::string(70000, 'b')).ok());
  ASSERT_TRUE(file.Patch(7, "1234").ok());
  ASSERT_TRUE(file.Append(";end").ok());
  EXPECT_EQ(file.size(), 70016u);
  ASSERT_TRUE(file.Close().ok());
  EXPECT_EQ(ReadBytes(path), "header:1234;" + std::string(70000, 'b') + ";end");
  EXPECT_FALSE(file.Append("more").ok()) << "a closed sink takes nothing";
}

TEST(ByteSinkTest, AFileIsOpenedByTheFirstByteAndRemovedUnlessWrittenInFull) {
  const std::string path = TempPath("kept.bin");
  WriteBytes(path, "what was there");
  { FileSink unused(path); }  // A writer that failed before its first byte.
  EXPECT_EQ(ReadBytes(path), "what was there");
  {
    FileSink abandoned(path);
    ASSERT_TRUE(abandoned.Append("half of it").ok());
  }  // A writer that failed on the way: no partly written file.
  EXPECT_FALSE(std::filesystem::exists(path));
  FileSink empty(path);
  ASSERT_TRUE(empty.Close().ok());
  EXPECT_TRUE(std::filesystem::exists(path));
  EXPECT_EQ(std::filesystem::file_size(path), 0u);

  const std::string missing = TempPath("no_such_dir/x.laz");
  FileSink nowhere(missing);
  const absl::Status status = nowhere.Append("bytes");
  EXPECT_EQ(status.code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(std::string(status.message()),
              HasSubstr("cannot write '" + missing + "': " + std::strerror(ENOENT)));
  EXPECT_EQ(nowhere.status(), status);
  EXPECT_EQ(nowhere.Close(), status);
}

TEST(ByteSinkTest, ADeviceOrAPipeTakesAppends) {
  // A full disk: the error says so, and the device is not removed.
  FileSink full("/dev/full");
  const absl::Status status = full.Append("bytes");
  EXPECT_EQ(status.code(), absl::StatusCode::kResourceExhausted) << status;
  EXPECT_THAT(std::string(status.message()), HasSubstr(std::strerror(ENOSPC)));
  EXPECT_EQ(full.Close(), status);
  EXPECT_TRUE(std::filesystem::exists("/dev/full"));

  int ends[2];
  ASSERT_EQ(::pipe(ends), 0);
  {
    FileSink pipe(absl::StrCat("/proc/self/fd/", ends[1]));
    ASSERT_TRUE(pipe.Append("through ").ok());
    ASSERT_TRUE(pipe.Append("a pipe").ok());
    const absl::Status patch = pipe.Patch(0, "T");
    EXPECT_THAT(std::string(patch.message()), HasSubstr(std::strerror(ESPIPE))) << patch;
    EXPECT_FALSE(pipe.Close().ok());
  }
  ::close(ends[1]);
  char read[64] = {};
  const ssize_t got = ::read(ends[0], read, sizeof(read));
  ::close(ends[0]);
  EXPECT_EQ(std::string(read, got > 0 ? got : 0), "through a pipe");
}

}  // namespace
}  // namespace neuralmesh
