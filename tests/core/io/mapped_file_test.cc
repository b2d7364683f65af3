#include "core/io/mapped_file.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/match.h"
#include "core/io/internal/shrink_guard.h"
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

// A file of `size` bytes of 0xab.
std::string WriteFile(const std::string& name, size_t size) {
  const std::string path = testing::ProcessTempDir() + "/" + name;
  std::ofstream(path, std::ios::binary) << std::string(size, '\xab');
  return path;
}

// Reads byte `i` of `data` so that the compiler cannot drop or move the read.
char ByteAt(absl::string_view data, size_t i) {
  return *static_cast<const volatile char*>(data.data() + i);
}

TEST(MappedFileTest, AFileThatShrinksReadsAsZerosPastItsNewEndAndSaysSo) {
  const std::string path = WriteFile("shrinks.bin", 65536);
  absl::StatusOr<MappedFile> file = MappedFile::Open(path);
  ASSERT_TRUE(file.ok()) << file.status();
  EXPECT_TRUE(file->CheckSize().ok()) << file->CheckSize();
  ASSERT_EQ(::truncate(path.c_str(), 5000), 0);
  EXPECT_EQ(ByteAt(file->data(), 4999), '\xab') << "before the new end: the file's bytes";
  EXPECT_EQ(ByteAt(file->data(), 6000), 0) << "in the last page, past the end: zeros";
  EXPECT_EQ(ByteAt(file->data(), 40000), 0) << "a page past the end: a SIGBUS, caught";
  EXPECT_EQ(ByteAt(file->data(), 65535), 0);
  const absl::Status size = file->CheckSize();
  EXPECT_EQ(size.code(), absl::StatusCode::kDataLoss) << size;
  EXPECT_EQ(size.message(), "'" + path +
                                "' shrank from 65536 to 5000 bytes while it was read; what lay "
                                "past its new end is gone");
}

TEST(MappedFileTest, AFaultPastTheEndIsReportedEvenWhenTheFileGrowsBack) {
  const std::string path = WriteFile("regrows.bin", 65536);
  absl::StatusOr<MappedFile> file = MappedFile::Open(path);
  ASSERT_TRUE(file.ok()) << file.status();
  ASSERT_EQ(::truncate(path.c_str(), 4096), 0);
  EXPECT_EQ(ByteAt(file->data(), 30000), 0);
  ASSERT_EQ(::truncate(path.c_str(), 65536), 0);
  EXPECT_EQ(file->CheckSize().code(), absl::StatusCode::kDataLoss)
      << "the zeros read are not the file's bytes";
}

TEST(MappedFileTest, ClosedMappingsFreeTheirGuardForNewOnes) {
  const std::string path = WriteFile("many.bin", 20000);
  for (int i = 0; i < 3 * io_internal::kMaxGuardedRanges; ++i) {
    ASSERT_TRUE(MappedFile::Open(path).ok());
  }
  std::vector<MappedFile> open;  // All the slots but one taken.
  for (int i = 0; i + 1 < io_internal::kMaxGuardedRanges; ++i) {
    absl::StatusOr<MappedFile> file = MappedFile::Open(path);
    ASSERT_TRUE(file.ok()) << file.status();
    open.push_back(*std::move(file));
  }
  absl::StatusOr<MappedFile> last = MappedFile::Open(path);
  ASSERT_TRUE(last.ok()) << last.status();
  ASSERT_EQ(::truncate(path.c_str(), 100), 0);
  EXPECT_EQ(ByteAt(last->data(), 12000), 0) << "the last slot guards it";
  EXPECT_EQ(last->CheckSize().code(), absl::StatusCode::kDataLoss);
  EXPECT_EQ(ByteAt(open.front().data(), 19999), 0);
}

#ifdef __SANITIZE_ADDRESS__
// AddressSanitizer's handler, installed before the guard's, reports the fault and exits.
constexpr bool kSanitizerHandlesSigbus = true;
#else
constexpr bool kSanitizerHandlesSigbus = false;
#endif

bool DiedOfSigbus(int status) {
  if (kSanitizerHandlesSigbus) return WIFEXITED(status) && WEXITSTATUS(status) != 0;
  return WIFSIGNALED(status) && WTERMSIG(status) == SIGBUS;
}

// The guard catches faults in its own ranges only: a read past the end of a file mapped
// elsewhere still goes to the handler before it, or kills the process with SIGBUS as it would
// without the guard.
TEST(MappedFileDeathTest, AFaultOutsideTheGuardedMappingsStillKills) {
  const std::string path = WriteFile("unguarded.bin", 65536);
  absl::StatusOr<MappedFile> guarded = MappedFile::Open(path);  // The handler is installed.
  ASSERT_TRUE(guarded.ok()) << guarded.status();
  const int fd = ::open(path.c_str(), O_RDONLY);
  ASSERT_GE(fd, 0);
  void* unguarded = ::mmap(nullptr, 65536, PROT_READ, MAP_PRIVATE, fd, 0);
  ASSERT_NE(unguarded, MAP_FAILED);
  EXPECT_EXIT(
      {
        if (::truncate(path.c_str(), 100) != 0) _exit(0);
        (void)ByteAt(absl::string_view(static_cast<const char*>(unguarded), 65536), 40000);
        _exit(0);
      },
      DiedOfSigbus, kSanitizerHandlesSigbus ? "BUS" : "");
  ::munmap(unguarded, 65536);
  ::close(fd);
}

}  // namespace
}  // namespace neuralmesh
