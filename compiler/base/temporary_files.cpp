// Temporary files (see temporary_files.hpp).
#include "base/temporary_files.hpp"

#include <signal.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>

namespace sicm {

std::string temporary_directory() {
  const char *tmp = std::getenv("TMPDIR");
  return tmp && tmp[0] == '/' ? tmp : "/tmp";
}

namespace {

constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP};
struct sigaction g_previous[3];
// The path, in static memory: the handler may only call async-signal-safe
// functions (unlink, sigaction, raise).
char g_path[4096];

extern "C" void remove_and_resignal(int sig) {
  if (g_path[0]) unlink(g_path);
  for (size_t i = 0; i < 3; ++i)
    if (kSignals[i] == sig) sigaction(sig, &g_previous[i], nullptr);
  raise(sig);
}

} // namespace

RemovedIfInterrupted::RemovedIfInterrupted(const std::string &path) {
  if (path.size() >= sizeof g_path) return; // too long to keep: left to the caller
  std::memcpy(g_path, path.c_str(), path.size() + 1);
  struct sigaction action {};
  action.sa_handler = remove_and_resignal;
  sigemptyset(&action.sa_mask);
  for (size_t i = 0; i < 3; ++i)
    sigaction(kSignals[i], &action, &g_previous[i]);
}

RemovedIfInterrupted::~RemovedIfInterrupted() {
  if (!g_path[0]) return;
  for (size_t i = 0; i < 3; ++i)
    sigaction(kSignals[i], &g_previous[i], nullptr);
  g_path[0] = '\0';
}

} // namespace sicm
