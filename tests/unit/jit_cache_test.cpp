// Unit tests of the kernel cache: SHA-256, sealed entries, bad entries rebuilt, concurrent runs.
//
// Each test points XDG_CACHE_HOME at a fresh directory. The process keeps a
// table of the objects it has loaded, by path, and never rereads those, so a
// test that damages an entry first builds it in one cache directory, then
// copies the directory and damages the copy: the copy's path is new to the
// process, and loading from it goes through the checks.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "codegen/jit.hpp"
#include "test_files.hpp"

using namespace sicm;

namespace {

using sicm_test::slurp;

using KernelFn = void (*)(const double *in, double *out, const double *p);

constexpr size_t kTrailerSize = 88; // jit.cpp: magic, key, SHA-256, length

// The temporary directories the tests made, removed when the program ends
// (forked children leave with _exit, which skips this).
struct TempDirs {
  std::vector<std::string> paths;
  ~TempDirs() {
    std::error_code ignored;
    for (const std::string &p : paths)
      std::filesystem::remove_all(p, ignored);
  }
} g_temp_dirs;

std::string temp_dir() {
  std::string dir = sicm_test::make_temp_dir("jitcache");
  g_temp_dirs.paths.push_back(dir);
  return dir;
}

void spit(const std::string &path, const std::string &bytes, mode_t mode = 0600) {
  std::remove(path.c_str());
  int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL, mode);
  ASSERT_GE(fd, 0) << path;
  ASSERT_EQ(write(fd, bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
  close(fd);
  ASSERT_EQ(chmod(path.c_str(), mode), 0);
}

std::string basename_of(const std::string &path) {
  return path.substr(path.rfind('/') + 1);
}

std::vector<std::string> listing(const std::string &dir) {
  std::vector<std::string> names;
  if (DIR *d = opendir(dir.c_str())) {
    while (dirent *e = readdir(d))
      if (e->d_name[0] != '.') names.push_back(e->d_name);
    closedir(d);
  }
  return names;
}

// Set an environment variable for the life of the object, then restore it.
class ScopedEnv {
public:
  ScopedEnv(const char *name, const std::string &value) : name_(name) {
    const char *old = std::getenv(name);
    had_ = old != nullptr;
    if (had_) old_ = old;
    setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (had_)
      setenv(name_, old_.c_str(), 1);
    else
      unsetenv(name_);
  }

private:
  const char *name_;
  bool had_;
  std::string old_;
};

// A kernel `symbol` computing out[0] = in[0] * factor; the tag makes the
// source (and so the cache key) unique to one test.
std::string kernel_source(const std::string &symbol, int factor, const std::string &tag) {
  return "/* " + tag + " */\nvoid " + symbol +
         "(const double *in, double *out, const double *p);\n"
         "void " +
         symbol +
         "(const double *in, double *out, const double *p) {\n  (void)p;\n  out[0] = in[0] * " +
         std::to_string(factor) + ".0;\n}\n";
}

// Load source from the cache at XDG_CACHE_HOME and run it on 1.0; NAN if it
// does not load.
double load_and_call(const std::string &source, const std::string &symbol,
                     std::string *so = nullptr) {
  std::string why, path;
  void *fn = jit_load(source, symbol, &path, &why);
  if (so) *so = path;
  EXPECT_NE(fn, nullptr) << why;
  if (!fn) return NAN;
  double in = 1.0, out = 0.0;
  reinterpret_cast<KernelFn>(fn)(&in, &out, nullptr);
  return out;
}

// Is the file at path an object sealed as jit.cpp seals it: a trailer whose
// SHA-256 is that of the bytes before it, private to this user?
bool sealed(const std::string &path) {
  std::string bytes = slurp(path);
  if (bytes.size() < kTrailerSize) return false;
  size_t n = bytes.size() - kTrailerSize;
  std::string_view seal(bytes.data() + n, kTrailerSize);
  std::string recorded;
  for (unsigned char c : seal.substr(48, 32)) {
    char two[3];
    std::snprintf(two, sizeof two, "%02x", c);
    recorded += two;
  }
  struct stat st;
  return seal.substr(0, 16) == "\nsicm-kernel-v1\n" &&
         recorded == jit_sha256(std::string_view(bytes.data(), n)) &&
         lstat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) && (st.st_mode & 077) == 0;
}

// A cache directory holding sealed entries for the sources (built in it and
// loaded by this process), and the path of each entry.
struct Built {
  std::string base; // XDG_CACHE_HOME
  std::vector<std::string> entries;
};

Built build_cache(const std::vector<std::pair<std::string, std::string>> &sources) {
  Built b{temp_dir(), {}};
  ScopedEnv cache("XDG_CACHE_HOME", b.base);
  for (const auto &[source, symbol] : sources) {
    std::string so;
    load_and_call(source, symbol, &so);
    b.entries.push_back(so);
  }
  return b;
}

// A fresh XDG_CACHE_HOME whose sicm directory is a copy of b's; returns its
// sicm directory.
std::string copy_cache(const Built &b, std::string *base) {
  *base = temp_dir();
  std::string dir = *base + "/sicm";
  EXPECT_EQ(mkdir(dir.c_str(), 0700), 0);
  for (const std::string &name : listing(b.base + "/sicm"))
    spit(dir + "/" + name, slurp(b.base + "/sicm/" + name));
  return dir;
}

// Damage the copy of entry 0 with `damage`, then load source 0 from the copy:
// it must be compiled again, give factor, and leave a sealed entry.
template <class Damage>
void expect_rebuilt(const std::string &source, const std::string &symbol, double factor,
                    const Built &b, Damage damage) {
  std::string base;
  std::string dir = copy_cache(b, &base);
  std::string entry = dir + "/" + basename_of(b.entries[0]);
  damage(entry, dir);
  ScopedEnv cache("XDG_CACHE_HOME", base);
  uint64_t before = jit_compiler_runs();
  std::string so;
  EXPECT_EQ(load_and_call(source, symbol, &so), factor);
  EXPECT_EQ(so, entry);
  EXPECT_EQ(jit_compiler_runs(), before + 1) << "the damaged entry was not rebuilt";
  EXPECT_TRUE(sealed(entry));
}

const char *sicm_binary() {
  const char *env = std::getenv("SICM_BINARY");
  return env ? env : "build/sicm";
}

} // namespace

TEST(JitCache, Sha256KnownAnswers) {
  // FIPS 180-4 examples (NIST CSRC, SHA256.pdf and SHA2_Additional.pdf).
  EXPECT_EQ(jit_sha256(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(jit_sha256("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(jit_sha256("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(jit_sha256("abcdefghbcdefghicdefghijdefghijkefghijklfghijklmghijklmnhijklmnoijklmnop"
                       "jklmnopqklmnopqrlmnopqrsmnopqrstnopqrstu"),
            "cf5b16a778af8380036ce59e7b0492370b249b11e8f07a51afac45037afee9d1");
  EXPECT_EQ(jit_sha256(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
  EXPECT_EQ(jit_hash("abc"), jit_sha256("abc").substr(0, 32));
}

TEST(JitCache, EntriesAreSealedAndPrivate) {
  std::string base = temp_dir();
  ScopedEnv cache("XDG_CACHE_HOME", base);
  std::string so;
  EXPECT_EQ(load_and_call(kernel_source("f", 3, "sealed"), "f", &so), 3.0);
  EXPECT_TRUE(sealed(so)) << so;
  struct stat st;
  ASSERT_EQ(stat((base + "/sicm").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 077, 0u);
}

TEST(JitCache, TruncatedEntryIsRebuilt) {
  std::string source = kernel_source("f", 5, "truncated");
  Built b = build_cache({{source, "f"}});
  size_t size = slurp(b.entries[0]).size();
  for (size_t keep : {size_t(0), size_t(16), size / 2, size - kTrailerSize, size - 1}) {
    SCOPED_TRACE("truncated to " + std::to_string(keep) + " of " + std::to_string(size));
    expect_rebuilt(source, "f", 5.0, b, [&](const std::string &entry, const std::string &) {
      ASSERT_EQ(truncate(entry.c_str(), static_cast<off_t>(keep)), 0);
    });
  }
}

TEST(JitCache, CorruptedByteIsRebuilt) {
  std::string source = kernel_source("f", 6, "corrupt");
  Built b = build_cache({{source, "f"}});
  size_t size = slurp(b.entries[0]).size();
  // A byte of padding between sections loads fine: only the hash sees it.
  for (size_t at : {size_t(100), size / 2, size - kTrailerSize - 1, size - 1}) {
    SCOPED_TRACE("byte " + std::to_string(at) + " of " + std::to_string(size));
    expect_rebuilt(source, "f", 6.0, b, [&](const std::string &entry, const std::string &) {
      std::string bytes = slurp(entry);
      bytes[at] ^= 0x20;
      spit(entry, bytes);
    });
  }
}

TEST(JitCache, AnotherKernelsObjectIsNotLoaded) {
  // Same symbol, different bodies: loading the wrong object would silently
  // give 8 instead of 7.
  std::string a = kernel_source("f", 7, "other-a"), b = kernel_source("f", 8, "other-b");
  Built built = build_cache({{a, "f"}, {b, "f"}});
  std::string a_bytes = slurp(built.entries[0]), b_bytes = slurp(built.entries[1]);
  ASSERT_NE(a_bytes, b_bytes);
  std::string b_object = b_bytes.substr(0, b_bytes.size() - kTrailerSize);
  std::string a_trailer = a_bytes.substr(a_bytes.size() - kTrailerSize);
  {
    SCOPED_TRACE("b's whole entry, trailer and all");
    expect_rebuilt(a, "f", 7.0, built,
                   [&](const std::string &entry, const std::string &) { spit(entry, b_bytes); });
  }
  {
    SCOPED_TRACE("b's object with a's trailer copied on");
    expect_rebuilt(a, "f", 7.0, built, [&](const std::string &entry, const std::string &) {
      spit(entry, b_object + a_trailer);
    });
  }
  {
    SCOPED_TRACE("b's object, unsealed (a stray file, or one from an older sicm)");
    expect_rebuilt(a, "f", 7.0, built,
                   [&](const std::string &entry, const std::string &) { spit(entry, b_object); });
  }
}

TEST(JitCache, EntryOthersCouldWriteIsNotLoaded) {
  std::string source = kernel_source("f", 9, "modes");
  Built b = build_cache({{source, "f"}});
  for (mode_t mode : {mode_t(0620), mode_t(0602), mode_t(0666)}) {
    SCOPED_TRACE("mode " + std::to_string(mode));
    expect_rebuilt(source, "f", 9.0, b, [&](const std::string &entry, const std::string &) {
      ASSERT_EQ(chmod(entry.c_str(), mode), 0);
    });
  }
}

TEST(JitCache, SymbolicLinkIsNotFollowed) {
  std::string source = kernel_source("f", 10, "symlink");
  Built b = build_cache({{source, "f"}});
  expect_rebuilt(source, "f", 10.0, b, [&](const std::string &entry, const std::string &dir) {
    std::string elsewhere = dir + "/../elsewhere.so";
    spit(elsewhere, slurp(entry));
    std::remove(entry.c_str());
    ASSERT_EQ(symlink(elsewhere.c_str(), entry.c_str()), 0);
  });
}

TEST(JitCache, DirectoryOthersCouldWriteIsNotUsed) {
  std::string base = temp_dir();
  std::string shared = base + "/sicm";
  ASSERT_EQ(mkdir(shared.c_str(), 0700), 0);
  ASSERT_EQ(chmod(shared.c_str(), 0777), 0);
  ScopedEnv cache("XDG_CACHE_HOME", base);
  EXPECT_NE(jit_cache_dir(), shared);
  std::string so;
  EXPECT_EQ(load_and_call(kernel_source("f", 11, "shared-dir"), "f", &so), 11.0);
  EXPECT_NE(so.rfind(shared, 0), 0u) << so;
  EXPECT_TRUE(listing(shared).empty());
}

TEST(JitCache, WarmHitDoesNotCompile) {
  std::string source = kernel_source("f", 12, "warm");
  Built b = build_cache({{source, "f"}});
  std::string base;
  copy_cache(b, &base); // a path this process has not loaded: the checks run
  ScopedEnv cache("XDG_CACHE_HOME", base);
  uint64_t before = jit_compiler_runs();
  EXPECT_EQ(load_and_call(source, "f"), 12.0);
  EXPECT_EQ(jit_compiler_runs(), before);
}

TEST(JitCache, ConcurrentThreadsAllLoad) {
  std::string base = temp_dir();
  ScopedEnv cache("XDG_CACHE_HOME", base);
  std::string source = kernel_source("f", 13, "threads");
  constexpr int kThreads = 8;
  std::atomic<int> ready{0}, good{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < kThreads; ++i)
    threads.emplace_back([&] {
      ++ready;
      while (ready.load() < kThreads) {
      }
      std::string why;
      void *fn = jit_load(source, "f", nullptr, &why);
      double in = 2.0, out = 0.0;
      if (fn) reinterpret_cast<KernelFn>(fn)(&in, &out, nullptr);
      if (out == 26.0) ++good;
    });
  for (std::thread &t : threads)
    t.join();
  EXPECT_EQ(good.load(), kThreads);
  for (const std::string &name : listing(base + "/sicm"))
    EXPECT_EQ(name.find(".tmp"), std::string::npos) << name;
}

// Processes forked together, each loading the same new kernel from the same
// cache the moment a pipe closes: every one must load it and compute with it.
TEST(JitCache, ConcurrentProcessesAllLoad) {
  for (int round = 0; round < 3; ++round) {
    std::string base = temp_dir();
    ScopedEnv cache("XDG_CACHE_HOME", base);
    std::string source = kernel_source("f", 14 + round, "processes");
    int gate[2];
    ASSERT_EQ(pipe(gate), 0);
    std::vector<pid_t> children;
    for (int i = 0; i < 6; ++i) {
      pid_t pid = fork();
      ASSERT_GE(pid, 0);
      if (pid == 0) {
        close(gate[1]);
        char c;
        while (read(gate[0], &c, 1) > 0) {
        }
        void *fn = jit_load(source, "f", nullptr, nullptr);
        double in = 1.0, out = 0.0;
        if (fn) reinterpret_cast<KernelFn>(fn)(&in, &out, nullptr);
        _exit(out == 14.0 + round ? 0 : 1);
      }
      children.push_back(pid);
    }
    close(gate[0]);
    close(gate[1]); // go
    for (pid_t pid : children) {
      int status = 0;
      ASSERT_EQ(waitpid(pid, &status, 0), pid);
      EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "round " << round;
    }
    std::vector<std::string> names = listing(base + "/sicm");
    EXPECT_EQ(names.size(), 2u); // KEY.so and KEY.c, no temporary files
    for (const std::string &name : names) {
      if (name.size() > 3 && name.substr(name.size() - 3) == ".so") {
        EXPECT_TRUE(sealed(base + "/sicm/" + name));
      }
    }
  }
}

// The real case: `sicm run` of one program, several at once, on a cold
// cache, then once more on a cache whose entry was truncated.
TEST(JitCache, ConcurrentSicmRunsShareTheCache) {
  struct stat st;
  if (stat(sicm_binary(), &st) != 0) GTEST_SKIP() << "no sicm binary at " << sicm_binary();
  std::string dir = temp_dir();
  std::string prog = dir + "/triple.sicm";
  std::ofstream(prog) << "(define (triple-plus x y) (+ (* 3 x) y))\n"
                         "(define k (compile-procedure triple-plus 1. 2.))\n"
                         "(display (list (kernel? k) (k 2. 1.)))\n"
                         "(newline)\n";
  ScopedEnv cache("XDG_CACHE_HOME", dir + "/cache");
  auto run_many = [&](int n, const std::string &tag) {
    std::vector<pid_t> pids;
    for (int i = 0; i < n; ++i) {
      pid_t pid = fork();
      ASSERT_GE(pid, 0);
      if (pid == 0) {
        std::string out = dir + "/" + tag + std::to_string(i);
        dup2(open((out + ".out").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600), 1);
        dup2(open((out + ".err").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600), 2);
        execl(sicm_binary(), "sicm", "run", prog.c_str(), (char *)nullptr);
        _exit(127);
      }
      pids.push_back(pid);
    }
    for (int i = 0; i < n; ++i) {
      int status = 0;
      ASSERT_EQ(waitpid(pids[i], &status, 0), pids[i]);
      std::string out = dir + "/" + tag + std::to_string(i);
      EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << slurp(out + ".err");
      EXPECT_EQ(slurp(out + ".out"), "(#t 7.)\n") << slurp(out + ".err");
      EXPECT_EQ(slurp(out + ".err"), "");
    }
  };
  run_many(4, "cold");
  std::string so;
  for (const std::string &name : listing(dir + "/cache/sicm")) {
    EXPECT_EQ(name.find(".tmp"), std::string::npos) << name;
    if (name.size() > 3 && name.substr(name.size() - 3) == ".so") so = dir + "/cache/sicm/" + name;
  }
  ASSERT_FALSE(so.empty());
  ASSERT_TRUE(sealed(so));
  ASSERT_EQ(truncate(so.c_str(), 1000), 0);
  run_many(2, "truncated");
  EXPECT_TRUE(sealed(so));
}
