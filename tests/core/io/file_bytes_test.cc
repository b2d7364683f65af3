#include "core/io/file_bytes.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <thread>

#include "gtest/gtest.h"
#include "tests/testing/temp_dir.h"

namespace neuralmesh {
namespace {

// A regular file's bytes are mapped, and a file that shrinks meanwhile is reported; a named
// pipe is read whole, once; missing and empty files are refused as ReadFileContents refuses
// them.
TEST(FileBytesTest, RegularFilesAreMappedOthersReadAndMissingOnesRefused) {
  const std::string dir = testing::MakeTempDir("file_bytes");
  std::string bytes(3 << 20, '\0');
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>(i * 13);
  const std::string path = dir + "/scan.las";
  std::ofstream(path, std::ios::binary) << bytes;
  absl::StatusOr<FileBytes> file = FileBytes::Read(path);
  ASSERT_TRUE(file.ok()) << file.status();
  EXPECT_EQ(file->data(), bytes);
  EXPECT_TRUE(file->CheckSize().ok());
  ASSERT_EQ(::truncate(path.c_str(), 1000), 0);
  const absl::Status shrank = file->CheckSize();
  EXPECT_EQ(shrank.code(), absl::StatusCode::kDataLoss) << shrank;

  const std::string fifo = dir + "/piped.las";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::thread writer([&] { std::ofstream(fifo, std::ios::binary) << bytes.substr(0, 70000); });
  absl::StatusOr<FileBytes> piped = FileBytes::Read(fifo);
  writer.join();
  ASSERT_TRUE(piped.ok()) << piped.status();
  EXPECT_EQ(piped->data(), bytes.substr(0, 70000));
  EXPECT_TRUE(piped->CheckSize().ok());

  absl::StatusOr<FileBytes> missing = FileBytes::Read(dir + "/missing.las");
  EXPECT_EQ(missing.status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(missing.status().message(),
            "cannot open '" + dir + "/missing.las': No such file or directory");
  std::ofstream(dir + "/empty.las");
  absl::StatusOr<FileBytes> empty = FileBytes::Read(dir + "/empty.las");
  EXPECT_EQ(empty.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(empty.status().message(), "'" + dir + "/empty.las' is empty");
}

}  // namespace
}  // namespace neuralmesh
