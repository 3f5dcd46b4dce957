#include "study/child_run.h"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace shellmpm {

namespace {

std::string tail_of(const std::string& path, std::size_t max_chars) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string s = ss.str();
  if (s.size() > max_chars) s = "..." + s.substr(s.size() - max_chars);
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s;
}

}  // namespace

ChildRunResult run_child(const ChildRunRequest& r) {
  std::vector<std::string> args = {r.binary, "run",     r.scene,     "--output",
                                   r.output, "--quiet", "--threads", std::to_string(r.threads)};
  if (!r.frames.empty()) {
    args.push_back("--frames");
    args.push_back(r.frames);
  }
  for (const std::string& o : r.overrides) {
    args.push_back("--set");
    args.push_back(o);
  }
  return run_process(args, r.log);
}

ChildRunResult run_process(const std::vector<std::string>& argv_in, const std::string& log) {
  std::vector<std::string> args = argv_in;
  std::vector<char*> argv;
  for (std::string& s : args) argv.push_back(s.data());
  argv.push_back(nullptr);

  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid < 0)
    throw std::runtime_error(std::string("cannot start ") + args[0] + ": " + std::strerror(errno));
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, 1);
      dup2(fd, 2);
      close(fd);
    }
    const int devnull = ::open("/dev/null", O_RDONLY);
    if (devnull >= 0) dup2(devnull, 0);
    execvp(argv[0], argv.data());
    _exit(127);
  }
  int status = 0;
  rusage ru{};
  while (wait4(pid, &status, 0, &ru) < 0) {
    if (errno != EINTR) throw std::runtime_error(std::string("wait4: ") + std::strerror(errno));
  }
  ChildRunResult out;
  out.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.peak_rss_bytes = static_cast<double>(ru.ru_maxrss) * 1024.0;  // Linux: kilobytes
  out.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  out.log_tail = tail_of(log, 600);
  return out;
}

}  // namespace shellmpm
