// Compiling generated C with the system compiler and loading it (see jit.hpp).
#include "codegen/jit.hpp"

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <unordered_map>
#include <vector>

#include <dlfcn.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

extern char **environ;

namespace sicm {

namespace {

std::atomic<uint64_t> g_compiler_runs{0};
std::atomic<uint64_t> g_temp_counter{0};
std::mutex g_mutex;                                  // the handle table and the fallback directory
std::unordered_map<std::string, void *> g_handles;   // so path -> dlopen handle
std::string g_fallback_dir;                          // made on first need
char g_fallback_path[4096];                          // a copy for the exit handler

// The fallback directory is private to this process: its files are removed
// as soon as they are loaded, the directory itself at exit.
void remove_fallback_dir() {
  if (g_fallback_path[0]) rmdir(g_fallback_path);
}

// The compiler command: $CC split on blanks, or cc.
std::vector<std::string> compiler_words() {
  std::vector<std::string> words;
  const char *cc = std::getenv("CC");
  std::string s = cc ? cc : "";
  size_t i = 0;
  while (i < s.size()) {
    size_t j = s.find_first_of(" \t", i);
    if (j == std::string::npos) j = s.size();
    if (j > i) words.push_back(s.substr(i, j - i));
    i = j + 1;
  }
  if (words.empty()) words.push_back("cc");
  return words;
}

const char *const kFlags[] = {"-std=c11", "-O2", "-fPIC", "-shared"};

uint64_t mix64(uint64_t x) { // splitmix64's finalizer
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  x ^= x >> 31;
  return x;
}

// mkdir -p with mode 0700 for what it creates; true if path is a directory at the end.
bool make_directories(const std::string &path) {
  for (size_t i = 1; i <= path.size(); ++i) {
    if (i < path.size() && path[i] != '/') continue;
    std::string prefix = path.substr(0, i);
    if (mkdir(prefix.c_str(), 0700) != 0 && errno != EEXIST) return false;
  }
  struct stat st;
  return stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

bool write_file(const std::string &path, const std::string &text) {
  int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) return false;
  size_t done = 0;
  while (done < text.size()) {
    ssize_t n = write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      close(fd);
      return false;
    }
    done += static_cast<size_t>(n);
  }
  return close(fd) == 0;
}

// The first lines of a compiler log, joined into one line.
std::string log_excerpt(const std::string &path) {
  std::FILE *f = std::fopen(path.c_str(), "r");
  if (!f) return "";
  char buf[1024];
  size_t n = std::fread(buf, 1, sizeof buf - 1, f);
  std::fclose(f);
  std::string s(buf, n);
  for (char &c : s)
    if (c == '\n' || c == '\t') c = ' ';
  while (!s.empty() && s.back() == ' ')
    s.pop_back();
  constexpr size_t kMax = 300;
  return s.size() > kMax ? s.substr(0, kMax) + "..." : s;
}

// Run argv with stdin from /dev/null and stdout and stderr to log. Returns
// the exit status, or -1 with errno_out set if it could not start.
int run_compiler(const std::vector<std::string> &argv, const std::string &log, int *errno_out) {
  std::vector<char *> cargv;
  for (const std::string &a : argv)
    cargv.push_back(const_cast<char *>(a.c_str()));
  cargv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  pid_t pid;
  ++g_compiler_runs;
  int rc = posix_spawnp(&pid, cargv[0], &fa, nullptr, cargv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) {
    *errno_out = rc;
    return -1;
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      *errno_out = errno;
      return -1;
    }
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

// Compile source into `so` (renamed into place). False with a reason on failure.
bool compile_to(const std::string &dir, const std::string &key, const std::string &source,
                const std::vector<std::string> &cc, const std::string &so, std::string *why_not) {
  std::string tmp = dir + "/" + key + "." + std::to_string(getpid()) + "." +
                    std::to_string(g_temp_counter++) + ".tmp";
  std::string src = tmp + ".c", out = tmp + ".so", log = tmp + ".log";
  if (!write_file(src, source)) {
    *why_not = "cannot write " + src + ": " + std::strerror(errno);
    return false;
  }
  std::vector<std::string> argv = cc;
  argv.insert(argv.end(), std::begin(kFlags), std::end(kFlags));
  argv.insert(argv.end(), {"-o", out, src, "-lm"});
  int err = 0;
  int status = run_compiler(argv, log, &err);
  bool ok = status == 0;
  if (status < 0 || status == 127)
    *why_not = "cannot run the C compiler '" + cc[0] + "'" +
               (status < 0 ? std::string(": ") + std::strerror(err) : std::string());
  else if (!ok)
    *why_not = "the C compiler '" + cc[0] + "' failed (exit status " + std::to_string(status) +
               "): " + log_excerpt(log);
  else if (std::rename(out.c_str(), so.c_str()) != 0) {
    *why_not = "cannot rename " + out + " to " + so + ": " + std::strerror(errno);
    ok = false;
  }
  // Keep the source beside its object for whoever wants to read it.
  if (ok) std::rename(src.c_str(), (dir + "/" + key + ".c").c_str());
  std::remove(src.c_str());
  std::remove(out.c_str());
  std::remove(log.c_str());
  return ok;
}

void *open_object(const std::string &so, std::string *error) {
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    auto h = g_handles.find(so);
    if (h != g_handles.end()) return h->second;
  }
  void *handle = dlopen(so.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    const char *e = dlerror();
    *error = e ? e : "dlopen failed";
    return nullptr;
  }
  std::lock_guard<std::mutex> lock(g_mutex);
  g_handles[so] = handle;
  return handle;
}

} // namespace

uint64_t jit_compiler_runs() {
  return g_compiler_runs.load();
}

std::string jit_hash(const std::string &text) {
  // Two independent 64-bit lanes over 8-byte words, finished with the length.
  uint64_t a = 0x243f6a8885a308d3ULL, b = 0x13198a2e03707344ULL;
  size_t i = 0;
  for (; i + 8 <= text.size(); i += 8) {
    uint64_t w;
    std::memcpy(&w, text.data() + i, 8);
    a = mix64(a ^ w) + 0x9e3779b97f4a7c15ULL;
    b = mix64(b + w * 0xff51afd7ed558ccdULL) ^ (b >> 29);
  }
  uint64_t w = 0;
  std::memcpy(&w, text.data() + i, text.size() - i);
  a = mix64(a ^ w ^ (static_cast<uint64_t>(text.size()) << 3));
  b = mix64(b + w * 0xff51afd7ed558ccdULL + text.size());
  a = mix64(a ^ b);
  char hex[33];
  std::snprintf(hex, sizeof hex, "%016llx%016llx", static_cast<unsigned long long>(a),
                static_cast<unsigned long long>(b));
  return hex;
}

std::string jit_cache_dir() {
  const char *xdg = std::getenv("XDG_CACHE_HOME");
  const char *home = std::getenv("HOME");
  std::string base;
  if (xdg && xdg[0] == '/')
    base = xdg;
  else if (home && home[0] == '/')
    base = std::string(home) + "/.cache";
  if (!base.empty() && make_directories(base + "/sicm")) return base + "/sicm";
  std::lock_guard<std::mutex> lock(g_mutex);
  if (g_fallback_dir.empty()) {
    const char *tmp = std::getenv("TMPDIR");
    std::string tmpl = std::string(tmp && tmp[0] == '/' ? tmp : "/tmp") + "/sicm-cache-XXXXXX";
    std::vector<char> buf(tmpl.begin(), tmpl.end());
    buf.push_back('\0');
    if (mkdtemp(buf.data()) && buf.size() < sizeof g_fallback_path) {
      g_fallback_dir = buf.data();
      std::memcpy(g_fallback_path, buf.data(), buf.size());
      std::atexit(remove_fallback_dir);
    }
  }
  return g_fallback_dir;
}

void *jit_load(const std::string &c_source, const std::string &symbol, std::string *so_path,
               std::string *why_not) {
  std::string ignored;
  if (!why_not) why_not = &ignored;
  std::vector<std::string> cc = compiler_words();
  std::string command;
  for (const std::string &w : cc)
    command += w + ' ';
  for (const char *f : kFlags)
    command += std::string(f) + ' ';
  std::string key = jit_hash(c_source + '\0' + command);
  std::string dir = jit_cache_dir();
  if (dir.empty()) {
    *why_not = "no directory for compiled kernels (the cache and the temporary directory "
               "cannot be created)";
    return nullptr;
  }
  std::string so = dir + "/" + key + ".so";
  if (so_path) *so_path = so;
  std::string error;
  void *handle = nullptr;
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    auto h = g_handles.find(so);
    if (h != g_handles.end()) handle = h->second;
  }
  if (!handle && access(so.c_str(), R_OK) == 0) handle = open_object(so, &error);
  if (!handle) { // not cached, or the cached file does not load: compile it anew
    if (!compile_to(dir, key, c_source, cc, so, why_not)) return nullptr;
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      g_handles.erase(so);
    }
    handle = open_object(so, &error);
    if (!handle) {
      *why_not = "cannot load the compiled kernel: " + error;
      return nullptr;
    }
    if (dir == g_fallback_dir) { // loaded: the mapping outlives the files
      std::remove(so.c_str());
      std::remove((dir + "/" + key + ".c").c_str());
    }
  }
  void *address = dlsym(handle, symbol.c_str());
  if (!address) *why_not = "the compiled kernel " + so + " has no symbol " + symbol;
  return address;
}

} // namespace sicm
