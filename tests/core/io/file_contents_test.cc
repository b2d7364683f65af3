#include "core/io/file_contents.h"

#include <sys/resource.h>

#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io/io_test_util.h"

namespace neuralmesh {
namespace {

using ::neuralmesh::io_test::TempPath;
using ::testing::HasSubstr;

TEST(FileContentsTest, WhatIsWrittenIsReadBack) {
  const std::string path = TempPath("contents.bin");
  std::string bytes("binary\0with\0zeros", 17);
  bytes.append(200000, 'x');
  ASSERT_TRUE(WriteFileContents(path, bytes).ok());
  const absl::StatusOr<std::string> read = ReadFileContents(path);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(*read, bytes);
  ASSERT_TRUE(WriteFileContents(path, "short").ok());
  EXPECT_EQ(*ReadFileContents(path), "short") << "a write replaces the whole file";
}

TEST(FileContentsTest, FailuresNameTheFileAndTheReason) {
  const std::string missing_dir = TempPath("no_such_dir/x.drc");
  const absl::Status write = WriteFileContents(missing_dir, "bytes");
  EXPECT_EQ(write.code(), absl::StatusCode::kNotFound) << write;
  EXPECT_THAT(std::string(write.message()),
              HasSubstr("cannot write '" + missing_dir + "': " + std::strerror(ENOENT)));

  const absl::StatusOr<std::string> absent = ReadFileContents(TempPath("absent.bin"));
  EXPECT_EQ(absent.status().code(), absl::StatusCode::kNotFound) << absent.status();
  EXPECT_THAT(std::string(absent.status().message()), HasSubstr("absent.bin"));

  const std::string empty = TempPath("empty.bin");
  std::ofstream(empty).close();
  const absl::StatusOr<std::string> nothing = ReadFileContents(empty);
  EXPECT_EQ(nothing.status().code(), absl::StatusCode::kInvalidArgument) << nothing.status();
  EXPECT_THAT(std::string(nothing.status().message()), HasSubstr("is empty"));

  const std::string dir = TempPath("a_directory");
  std::filesystem::create_directories(dir);
  EXPECT_EQ(ReadFileContents(dir).status().code(), absl::StatusCode::kNotFound);
}

// A write that fails midway (here: past the process's file-size limit, as a full disk would
// fail it) reports why and leaves no truncated file behind.
TEST(FileContentsTest, AWriteThatFailsMidwayLeavesNoFile) {
  const std::string path = TempPath("too_large.drc");
  rlimit saved;
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &saved), 0);
  const auto previous_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit small = saved;
  small.rlim_cur = 4096;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  const absl::Status status = WriteFileContents(path, std::string(1 << 20, 'x'));
  setrlimit(RLIMIT_FSIZE, &saved);
  std::signal(SIGXFSZ, previous_handler);

  EXPECT_FALSE(status.ok());
  EXPECT_THAT(std::string(status.message()),
              HasSubstr("cannot write '" + path + "': " + std::strerror(EFBIG)));
  EXPECT_FALSE(std::filesystem::exists(path)) << "the partly written file must be removed";
}

}  // namespace
}  // namespace neuralmesh
