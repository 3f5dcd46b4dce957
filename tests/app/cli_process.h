// Running the shellmpm binary as a child process the test controls: started without
// waiting (to send it signals), optionally under a file size limit (a write failure
// like a full disk's), its output in a log file.
#pragma once
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstddef>
#include <string>
#include <thread>
#include <vector>

#include "tests/app/cli_harness.h"

namespace shellmpm_test {

struct Child {
  pid_t pid = -1;
  std::string log;  ///< stdout and stderr go here
};

/// Starts `shellmpm ARGS...` with stdout and stderr into `log`. With `file_size_limit`
/// > 0, writes past that many bytes into any file fail with EFBIG (SIGXFSZ ignored).
inline Child spawn_shellmpm(const std::vector<std::string>& args, const std::string& log,
                            std::size_t file_size_limit = 0) {
  Child c;
  c.log = log;
  std::vector<std::string> argv_s = {SHELLMPM_BINARY};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& s : argv_s) argv.push_back(s.data());
  argv.push_back(nullptr);
  c.pid = fork();
  if (c.pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, 1);
      dup2(fd, 2);
    }
    // A foreground process, whatever the test runner ignores or blocks (a background
    // job of a non-interactive shell ignores SIGINT).
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    if (file_size_limit > 0) {
      signal(SIGXFSZ, SIG_IGN);
      rlimit r{};
      getrlimit(RLIMIT_FSIZE, &r);
      r.rlim_cur = file_size_limit;
      setrlimit(RLIMIT_FSIZE, &r);
    }
    execv(SHELLMPM_BINARY, argv.data());
    _exit(127);
  }
  return c;
}

/// Waits for the child; returns its exit code (minus the signal number when a signal
/// ended it, so that exit(143) and death by SIGTERM differ) and its output.
inline CmdResult wait_child(const Child& c) {
  int status = 0;
  waitpid(c.pid, &status, 0);
  CmdResult r;
  r.code = WIFEXITED(status)     ? WEXITSTATUS(status)
           : WIFSIGNALED(status) ? -WTERMSIG(status)
                                 : -1000;
  r.output = read_text(c.log);
  if (WIFSIGNALED(status))
    r.output += "\n[killed by signal " + std::to_string(WTERMSIG(status)) + "]";
  return r;
}

/// Waits until `path` exists (true) or `seconds` pass (false).
inline bool wait_for_file(const std::string& path, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!std::filesystem::exists(path)) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

}  // namespace shellmpm_test
