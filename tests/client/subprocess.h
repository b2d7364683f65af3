// Runs the project's binaries (build/bin, from NEURALMESH_BIN_DIR) as subprocesses for the
// end-to-end tests of the `neuralmesh` command line.
#ifndef NEURALMESH_TESTS_CLIENT_SUBPROCESS_H_
#define NEURALMESH_TESTS_CLIENT_SUBPROCESS_H_

#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/testing/temp_dir.h"

namespace neuralmesh::testing {

// The directory of the built binaries.
inline std::string BinDir() {
  const char* dir = std::getenv("NEURALMESH_BIN_DIR");
  return dir != nullptr ? dir : "build/bin";
}

inline std::string ReadWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

struct RunResult {
  int exit_code = -1;  // 128 + signal when killed by a signal.
  std::string out;
  std::string err;

  // For failure messages.
  std::string Describe() const {
    return "exit code " + std::to_string(exit_code) + "\n--- stdout:\n" + out + "\n--- stderr:\n" +
           err;
  }
};

namespace internal {
inline pid_t Spawn(const std::string& binary, const std::vector<std::string>& args,
                   const std::string& out_path, const std::string& err_path, int stdin_fd = -1) {
  std::vector<std::string> argv_storage = {binary};
  argv_storage.insert(argv_storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    const int out = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(out, STDOUT_FILENO);
    dup2(err, STDERR_FILENO);
    if (stdin_fd >= 0) dup2(stdin_fd, STDIN_FILENO);
    execv(binary.c_str(), argv.data());
    _exit(127);
  }
  return pid;
}

inline int WaitExitCode(pid_t pid) {
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return -1;
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}
}  // namespace internal

// Runs `bin_dir/name args...` to completion, capturing its output. A binary that was not
// built exits with 127 and says so on stderr.
inline RunResult RunBinary(const std::string& name, const std::vector<std::string>& args) {
  static int counter = 0;
  const std::string binary = BinDir() + "/" + name;
  if (!std::filesystem::exists(binary)) {
    return {127, "", binary + " does not exist: build it first (cmake --build build)"};
  }
  const std::string base = MakeTempDir("run") + "/" + std::to_string(counter++);
  const pid_t pid = internal::Spawn(binary, args, base + ".out", base + ".err");
  RunResult result;
  result.exit_code = internal::WaitExitCode(pid);
  result.out = ReadWholeFile(base + ".out");
  result.err = ReadWholeFile(base + ".err");
  return result;
}

inline RunResult RunNeuralmesh(const std::vector<std::string>& args) {
  return RunBinary("neuralmesh", args);
}

// A TCP port on 127.0.0.1 that was free a moment ago.
inline int PickFreePort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr));
  socklen_t len = sizeof(addr);
  getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  close(fd);
  return ntohs(addr.sin_port);
}

// A background process (a server) that is stopped (SIGTERM, then SIGKILL) on destruction.
// With `stdin_pipe`, its standard input is a pipe that WriteStdin feeds and CloseStdin ends.
class BackgroundProcess {
 public:
  BackgroundProcess(const std::string& name, const std::vector<std::string>& args,
                    bool stdin_pipe = false) {
    // A directory of its own: two processes of one name must not share their output files.
    static int counter = 0;
    const std::string base = MakeTempDir(name + "_" + std::to_string(counter++));
    out_path_ = base + "/stdout";
    err_path_ = base + "/stderr";
    int pipe_fds[2] = {-1, -1};
    if (stdin_pipe) {
      signal(SIGPIPE, SIG_IGN);  // A write after the process ended fails instead.
      if (pipe(pipe_fds) != 0) pipe_fds[0] = pipe_fds[1] = -1;
    }
    if (pipe_fds[1] >= 0) fcntl(pipe_fds[1], F_SETFD, FD_CLOEXEC);
    pid_ = internal::Spawn(BinDir() + "/" + name, args, out_path_, err_path_, pipe_fds[0]);
    if (pipe_fds[0] >= 0) close(pipe_fds[0]);
    stdin_ = pipe_fds[1];
  }
  ~BackgroundProcess() {
    CloseStdin();
    Stop();
  }

  // Writes `text` to its standard input (a pipe); whether all of it was written.
  bool WriteStdin(const std::string& text) {
    size_t written = 0;
    while (stdin_ >= 0 && written < text.size()) {
      const ssize_t n = write(stdin_, text.data() + written, text.size() - written);
      if (n <= 0) return false;
      written += static_cast<size_t>(n);
    }
    return written == text.size();
  }
  void CloseStdin() {
    if (stdin_ >= 0) close(stdin_);
    stdin_ = -1;
  }
  BackgroundProcess(const BackgroundProcess&) = delete;
  BackgroundProcess& operator=(const BackgroundProcess&) = delete;

  // Whether it still runs.
  bool Running() {
    int status = 0;
    if (pid_ > 0 && waitpid(pid_, &status, WNOHANG) != 0) {  // Exited and reaped.
      exit_code_ = WIFEXITED(status)     ? WEXITSTATUS(status)
                   : WIFSIGNALED(status) ? 128 + WTERMSIG(status)
                                         : -1;
      pid_ = -1;
    }
    return pid_ > 0;
  }
  // Its exit code as RunResult gives it, once Running() has seen it end; -1 before.
  int exit_code() const { return exit_code_; }
  // Sends `signal` without waiting (SIGSTOP freezes the process, SIGCONT resumes it).
  void Signal(int signal) {
    if (pid_ > 0) kill(pid_, signal);
  }
  // Sends `signal` and waits for the process to end; returns its exit code as RunResult does
  // (-1 when it had already ended).
  int SignalAndWait(int signal) {
    if (pid_ <= 0) return -1;
    kill(pid_, signal);
    const int code = internal::WaitExitCode(pid_);
    pid_ = -1;
    return code;
  }

  std::string Stdout() const { return ReadWholeFile(out_path_); }
  std::string Stderr() const { return ReadWholeFile(err_path_); }
  // Waits up to 5 s for the standard output (error) to hold `text`; whether it came.
  bool AwaitStdout(const std::string& text) const {
    return Await([this] { return Stdout(); }, text);
  }
  bool AwaitStderr(const std::string& text) const {
    return Await([this] { return Stderr(); }, text);
  }

  void Stop() {
    if (pid_ <= 0) return;
    kill(pid_, SIGTERM);
    for (int i = 0; i < 100; ++i) {
      if (waitpid(pid_, nullptr, WNOHANG) != 0) {
        pid_ = -1;
        return;
      }
      usleep(50 * 1000);
    }
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }

 private:
  template <typename Read>
  static bool Await(const Read& read, const std::string& text) {
    for (int i = 0; i < 100; ++i) {
      if (read().find(text) != std::string::npos) return true;
      usleep(50 * 1000);
    }
    return read().find(text) != std::string::npos;
  }

  pid_t pid_ = -1;
  int exit_code_ = -1;
  int stdin_ = -1;  // The pipe's end to write, or -1.
  std::string out_path_;
  std::string err_path_;
};

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_CLIENT_SUBPROCESS_H_
