#include "core/io/mapped_file.h"

#include <fstream>
#include <string>
#include <utility>

#include "absl/strings/match.h"
#include "gtest/gtest.h"
#include "tests/testing/temp_dir.h"

namespace neuralmesh {
namespace {

TEST(MappedFileTest, HoldsTheFilesBytesWhileItLivesMovedOrNot) {
  const std::string path = testing::ProcessTempDir() + "/bytes.bin";
  std::string bytes(100000, '\0');
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>(i * 7);
  std::ofstream(path, std::ios::binary) << bytes;
  absl::StatusOr<MappedFile> file = MappedFile::Open(path);
  ASSERT_TRUE(file.ok()) << file.status();
  EXPECT_EQ(file->data(), bytes);
  EXPECT_TRUE(file->read_ahead()) << "100 KB fit in memory";
  MappedFile moved = *std::move(file);
  EXPECT_EQ(moved.data(), bytes);
  EXPECT_TRUE(file->data().empty()) << "the moved-from object holds nothing";
  MappedFile other = std::move(moved);
  moved = std::move(other);
  EXPECT_EQ(moved.data(), bytes);
}

TEST(MappedFileTest, MissingEmptyAndNonRegularFilesAreRefusedSayingSo) {
  const std::string dir = testing::MakeTempDir("mapped");
  const auto expect = [](const std::string& path, absl::StatusCode code, const char* words) {
    absl::StatusOr<MappedFile> file = MappedFile::Open(path);
    ASSERT_FALSE(file.ok()) << path;
    EXPECT_EQ(file.status().code(), code) << file.status();
    EXPECT_TRUE(absl::StrContains(file.status().message(), words)) << file.status();
  };
  expect(dir + "/missing", absl::StatusCode::kNotFound, "cannot open '");
  expect(dir, absl::StatusCode::kNotFound, "Is a directory");
  std::ofstream(dir + "/empty");
  expect(dir + "/empty", absl::StatusCode::kInvalidArgument, "is empty");
}

}  // namespace
}  // namespace neuralmesh
