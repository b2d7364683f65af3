// Temporary files of tests: one directory per test process, under TEST_TMPDIR or /tmp, that
// is removed when the process exits, so that runs leave nothing behind (a process that
// crashes keeps its directory for a look).
#ifndef NEURALMESH_TESTS_TESTING_TEMP_DIR_H_
#define NEURALMESH_TESTS_TESTING_TEMP_DIR_H_

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace neuralmesh::testing {

// This process's directory, created on first use: neuralmesh_test_<pid>.
inline const std::string& ProcessTempDir() {
  static const std::string* const dir = [] {
    const char* base = std::getenv("TEST_TMPDIR");
    auto* path = new std::string(
        (std::filesystem::path(base != nullptr && *base != '\0' ? base : "/tmp") /
         ("neuralmesh_test_" + std::to_string(getpid())))
            .string());
    std::filesystem::remove_all(*path);
    std::filesystem::create_directories(*path);
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(ProcessTempDir(), ignored);
    });
    return path;
  }();
  return *dir;
}

// A fresh empty directory `name` in this process's directory.
inline std::string MakeTempDir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(ProcessTempDir()) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_TESTING_TEMP_DIR_H_
