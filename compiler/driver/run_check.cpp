// What `sicm run` does with a program the build refused (see run_check.hpp).
#include "driver/run_check.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "base/temporary_files.hpp"

namespace sicm {

namespace {

std::string format_seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", s);
  return buf;
}

} // namespace

std::string what_sicm_run_does(const std::string &file, double seconds) {
  std::string pattern = temporary_directory() + "/sicm-run-check-XXXXXX";
  std::vector<char> dir_template(pattern.begin(), pattern.end());
  dir_template.push_back('\0');
  if (!mkdtemp(dir_template.data())) return "";
  const std::string plots = dir_template.data();
  int err_pipe[2];
  if (pipe(err_pipe) != 0) {
    rmdir(plots.c_str());
    return "";
  }
  pid_t child = fork();
  if (child < 0) {
    close(err_pipe[0]);
    close(err_pipe[1]);
    rmdir(plots.c_str());
    return "";
  }
  if (child == 0) {
    setpgid(0, 0); // its own group: a C compiler it starts dies with it
    int null = open("/dev/null", O_RDWR);
    dup2(null, 0);
    dup2(null, 1);
    dup2(err_pipe[1], 2);
    close(err_pipe[0]);
    execl("/proc/self/exe", "sicm", "run", file.c_str(), "--plot-dir", plots.c_str(),
          static_cast<char *>(nullptr));
    _exit(127);
  }
  close(err_pipe[1]);
  fcntl(err_pipe[0], F_SETFL, O_NONBLOCK);
  std::string err;
  int status = 0;
  bool finished = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (true) {
    char buf[4096];
    ssize_t n;
    while ((n = read(err_pipe[0], buf, sizeof buf)) > 0)
      if (err.size() < 65536) err.append(buf, static_cast<size_t>(n));
    pid_t w = waitpid(child, &status, WNOHANG);
    if (w == child) {
      finished = true;
      while ((n = read(err_pipe[0], buf, sizeof buf)) > 0)
        if (err.size() < 65536) err.append(buf, static_cast<size_t>(n));
      break;
    }
    if (std::chrono::steady_clock::now() > deadline) {
      kill(-child, SIGKILL);
      kill(child, SIGKILL);
      waitpid(child, &status, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  close(err_pipe[0]);
  std::error_code ignored;
  std::filesystem::remove_all(plots, ignored);
  if (!finished)
    return "`sicm run` ran it for " + format_seconds(seconds) +
           " s without failing (stopped there)";
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return "`sicm run` interprets this program";
  std::string first = err.substr(0, err.find('\n'));
  if (first.empty()) return "`sicm run` fails on it too";
  return "`sicm run` fails on it too: " + first;
}

} // namespace sicm
