// tests/support/run_command.hpp -- run a command (no shell) and capture its stdout, stderr and exit
// code, for the end-to-end tests of ffsr-optimize.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

// fork + execv: the arguments go to the program exactly as given (no quoting problems with
// "--joints-deg=-2.29,..."), the child can run in another working directory, stdin is /dev/null,
// stdout and stderr go to two unlinked temporary files that are read back after the child exits.
// A child that runs longer than `timeout_s` is killed (SIGKILL) so a hanging command fails a test
// instead of blocking the suite.

namespace ffsr::test {

struct CommandResult {
  int exit_code = -1;      ///< exit status, or 128 + signal number when the child was killed
  bool signaled = false;   ///< the child died from a signal (crash or timeout)
  bool timed_out = false;  ///< killed after `timeout_s`
  std::string out;         ///< everything written to stdout
  std::string err;         ///< everything written to stderr
};

namespace detail {

/// An anonymous temporary file (already unlinked) open for reading and writing.
inline int anonymous_file() {
  std::string pattern = (std::filesystem::temp_directory_path() / "ffsr_cmd_XXXXXX").string();
  const int fd = ::mkstemp(pattern.data());
  if (fd < 0) throw std::system_error(errno, std::generic_category(), "mkstemp");
  ::unlink(pattern.c_str());
  return fd;
}

inline std::string read_all(int fd) {
  std::string s;
  ::lseek(fd, 0, SEEK_SET);
  char buf[65536];
  for (;;) {
    const ssize_t k = ::read(fd, buf, sizeof buf);
    if (k <= 0) break;
    s.append(buf, static_cast<size_t>(k));
  }
  return s;
}

/// Waits for the child `pid` to exit, killing it (SIGKILL) after `timeout_s`; its exit code, or 128 +
/// the signal number when a signal ended it.
inline CommandResult wait_for(pid_t pid, double timeout_s) {
  CommandResult r;
  int status = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  for (;;) {
    const pid_t w = ::waitpid(pid, &status, WNOHANG);
    if (w == pid) break;
    if (w < 0 && errno != EINTR) throw std::system_error(errno, std::generic_category(), "waitpid");
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      r.timed_out = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  if (WIFEXITED(status)) {
    r.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    r.signaled = true;
    r.exit_code = 128 + WTERMSIG(status);
  }
  return r;
}

}  // namespace detail

/// Runs args[0] (a path, not looked up in PATH) with args[1..] in `cwd` (empty: the current
/// directory) and returns what it printed and its exit code.
inline CommandResult run_command(const std::vector<std::string>& args, const std::string& cwd = {},
                                 double timeout_s = 120.0) {
  if (args.empty()) throw std::invalid_argument("run_command: no program");
  const int out_fd = detail::anonymous_file();
  const int err_fd = detail::anonymous_file();
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);

  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) throw std::system_error(errno, std::generic_category(), "fork");
  if (pid == 0) {  // child: only async-signal-safe calls from here on
    const int in_fd = ::open("/dev/null", O_RDONLY);
    if (in_fd >= 0) ::dup2(in_fd, 0);
    ::dup2(out_fd, 1);
    ::dup2(err_fd, 2);
    if (!cwd.empty() && ::chdir(cwd.c_str()) != 0) {
      static const char msg[] = "run_command: chdir failed\n";
      (void)!::write(2, msg, sizeof msg - 1);
      ::_exit(126);
    }
    ::execv(argv[0], argv.data());
    static const char msg[] = "run_command: execv failed\n";
    (void)!::write(2, msg, sizeof msg - 1);
    ::_exit(127);
  }

#if defined(FFSR_SANITIZED) && defined(__OPTIMIZE__)
  timeout_s *= 4.0;  // ASan + UBSan at -O1 (.ci/run) run the command a few times slower than Release
#elif defined(FFSR_SANITIZED)
  timeout_s *= 10.0;  // at -O0 with ASan + UBSan, an order of magnitude slower
#endif
  CommandResult r = detail::wait_for(pid, timeout_s);
  r.out = detail::read_all(out_fd);
  r.err = detail::read_all(err_fd);
  ::close(out_fd);
  ::close(err_fd);
  return r;
}

/// A fresh empty directory under the system temporary directory, removed with its content when the
/// object goes out of scope.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "ffsr_cli_XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr)
      throw std::system_error(errno, std::generic_category(), "mkdtemp");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::string str() const { return path_.string(); }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }
  /// Names of the entries in the directory (not recursive), sorted.
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(path_))
      names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  std::filesystem::path path_;
};

}  // namespace ffsr::test
