// Compiling generated C with the system compiler, sealing, caching and loading it (see jit.hpp).
//
// A cache entry is KEY.so, the compiler's output followed by a trailer of
// kTrailerSize bytes that only this file writes:
//
//   offset  0  16 bytes  kTrailerMagic
//   offset 16  32 bytes  the key: SHA-256 of the source, a NUL and the identity
//   offset 48  32 bytes  SHA-256 of the object (every byte before the trailer)
//   offset 80   8 bytes  the object's length, little-endian
//
// The dynamic loader maps an ELF object by its headers and ignores bytes past
// the end, so the sealed file loads as it is. One file carries both the
// object and its check, so one rename publishes both: a reader sees the old
// entry or the new one, never a new object with an old check. KEY.c, the
// source beside it, is for people to read and is never trusted.
//
// SHA-256 because the key and the check must be collision resistant, not
// merely well mixed: a name chosen by 128 bits of a non-cryptographic hash
// can be made to collide on purpose, SHA-256 cannot, and it is the vetted
// standard (FIPS 180-4) that needs no library sicm does not already link.
// It costs about 0.1 ms for a typical 15 KB object, once per kernel per run.
//
// There is no fsync: a crash that leaves a truncated or zero-filled entry
// behind is caught by the check and costs one recompilation.
#include "codegen/jit.hpp"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <sstream>
#include <unordered_map>
#include <vector>

#include <dlfcn.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/utsname.h>
#include <sys/wait.h>
#include <unistd.h>

#include "base/error.hpp"
#include "base/limits.hpp"

extern char **environ;

namespace sicm {

namespace {

// ---- SHA-256 (FIPS 180-4) ---------------------------------------------------

class Sha256 {
public:
  static constexpr size_t kSize = 32;

  void update(const void *data, size_t n) {
    const unsigned char *p = static_cast<const unsigned char *>(data);
    length_ += n;
    if (fill_) {
      size_t take = std::min(n, sizeof block_ - fill_);
      std::memcpy(block_ + fill_, p, take);
      fill_ += take;
      p += take;
      n -= take;
      if (fill_ < sizeof block_) return;
      compress(block_);
      fill_ = 0;
    }
    for (; n >= 64; p += 64, n -= 64)
      compress(p);
    std::memcpy(block_, p, n);
    fill_ = n;
  }

  void finish(unsigned char out[kSize]) {
    uint64_t bits = length_ * 8;
    unsigned char pad[72] = {0x80};
    size_t padlen = (fill_ < 56 ? 56 : 120) - fill_;
    for (int i = 0; i < 8; ++i)
      pad[padlen + i] = static_cast<unsigned char>(bits >> (56 - 8 * i));
    update(pad, padlen + 8);
    for (int i = 0; i < 8; ++i)
      for (int j = 0; j < 4; ++j)
        out[4 * i + j] = static_cast<unsigned char>(h_[i] >> (24 - 8 * j));
  }

private:
  static uint32_t rotr(uint32_t x, int n) { return (x >> n) | (x << (32 - n)); }

  // One round of FIPS 180-4 6.2.2 step 3, kw = K_t + W_t: the new a is left
  // in h and the new e in d.
  static void round(uint32_t a, uint32_t b, uint32_t c, uint32_t &d, uint32_t e, uint32_t f,
                    uint32_t g, uint32_t &h, uint32_t kw) {
    uint32_t t1 = h + (rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25)) + ((e & f) ^ (~e & g)) + kw;
    uint32_t t2 = (rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22)) + ((a & b) ^ (a & c) ^ (b & c));
    d += t1;
    h = t1 + t2;
  }

  void compress(const unsigned char *p) {
    static const uint32_t k[64] = {
        0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4,
        0xab1c5ed5, 0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe,
        0x9bdc06a7, 0xc19bf174, 0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f,
        0x4a7484aa, 0x5cb0a9dc, 0x76f988da, 0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7,
        0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967, 0x27b70a85, 0x2e1b2138, 0x4d2c6dfc,
        0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85, 0xa2bfe8a1, 0xa81a664b,
        0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070, 0x19a4c116,
        0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
        0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7,
        0xc67178f2};
    uint32_t w[64];
    for (int i = 0; i < 16; ++i)
      w[i] = uint32_t(p[4 * i]) << 24 | uint32_t(p[4 * i + 1]) << 16 | uint32_t(p[4 * i + 2]) << 8 |
             uint32_t(p[4 * i + 3]);
    for (int i = 16; i < 64; ++i) {
      uint32_t s0 = rotr(w[i - 15], 7) ^ rotr(w[i - 15], 18) ^ (w[i - 15] >> 3);
      uint32_t s1 = rotr(w[i - 2], 17) ^ rotr(w[i - 2], 19) ^ (w[i - 2] >> 10);
      w[i] = w[i - 16] + s0 + w[i - 7] + s1;
    }
    uint32_t a = h_[0], b = h_[1], c = h_[2], d = h_[3], e = h_[4], f = h_[5], g = h_[6], h = h_[7];
    // Eight rounds per pass with the roles of the variables rotated, instead
    // of shifting eight values along after every round.
    for (int i = 0; i < 64; i += 8) {
      round(a, b, c, d, e, f, g, h, k[i] + w[i]);
      round(h, a, b, c, d, e, f, g, k[i + 1] + w[i + 1]);
      round(g, h, a, b, c, d, e, f, k[i + 2] + w[i + 2]);
      round(f, g, h, a, b, c, d, e, k[i + 3] + w[i + 3]);
      round(e, f, g, h, a, b, c, d, k[i + 4] + w[i + 4]);
      round(d, e, f, g, h, a, b, c, k[i + 5] + w[i + 5]);
      round(c, d, e, f, g, h, a, b, k[i + 6] + w[i + 6]);
      round(b, c, d, e, f, g, h, a, k[i + 7] + w[i + 7]);
    }
    h_[0] += a;
    h_[1] += b;
    h_[2] += c;
    h_[3] += d;
    h_[4] += e;
    h_[5] += f;
    h_[6] += g;
    h_[7] += h;
  }

  uint32_t h_[8] = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                    0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
  unsigned char block_[64];
  size_t fill_ = 0;
  uint64_t length_ = 0;
};

using Digest = std::string; // Sha256::kSize raw bytes

Digest sha256(std::string_view text) {
  unsigned char out[Sha256::kSize];
  Sha256 s;
  s.update(text.data(), text.size());
  s.finish(out);
  return Digest(reinterpret_cast<char *>(out), sizeof out);
}

std::string hex(std::string_view bytes) {
  static const char digits[] = "0123456789abcdef";
  std::string s;
  for (unsigned char c : bytes) {
    s += digits[c >> 4];
    s += digits[c & 15];
  }
  return s;
}

// ---- the sealed entry -------------------------------------------------------

constexpr char kTrailerMagic[16] = {'\n', 's', 'i', 'c', 'm', '-', 'k', 'e',
                                    'r',  'n', 'e', 'l', '-', 'v', '1', '\n'};
constexpr size_t kTrailerSize = 16 + 2 * Sha256::kSize + 8;
// A cache entry larger than this is refused unread (kernels are kilobytes).
constexpr off_t kMaxEntrySize = off_t(64) << 20;

std::string trailer(const Digest &key, const Digest &object_digest, uint64_t object_size) {
  std::string t(kTrailerMagic, sizeof kTrailerMagic);
  t += key;
  t += object_digest;
  for (int i = 0; i < 8; ++i)
    t += static_cast<char>(object_size >> (8 * i));
  return t;
}

// Why st may not be trusted as a cache entry, or null if it may: a regular
// file of this user that no one else can write.
const char *untrusted_file(const struct stat &st) {
  if (!S_ISREG(st.st_mode)) return "not a regular file";
  if (st.st_uid != geteuid()) return "owned by another user";
  if (st.st_mode & (S_IWGRP | S_IWOTH)) return "writable by others";
  if (st.st_size > kMaxEntrySize) return "too large";
  return nullptr;
}

// The whole of the open file fd into *bytes. False on a read error or a
// short read.
bool read_all(int fd, size_t size, std::string *bytes) {
  bytes->resize(size);
  size_t done = 0;
  while (done < size) {
    ssize_t n = pread(fd, bytes->data() + done, size - done, static_cast<off_t>(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<size_t>(n);
  }
  return true;
}

bool write_all(int fd, const char *data, size_t size, off_t at) {
  size_t done = 0;
  while (done < size) {
    ssize_t n = pwrite(fd, data + done, size - done, at + static_cast<off_t>(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<size_t>(n);
  }
  return true;
}

// Check that the file at path is a sealed entry for key. False with the
// reason in *why if it is missing, untrusted, truncated or not for key.
bool verify_entry(const std::string &path, const Digest &key, std::string *why) {
  int fd = open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) {
    *why = errno == ENOENT ? "not cached" : std::string("cannot open: ") + std::strerror(errno);
    return false;
  }
  struct stat st;
  std::string bytes;
  bool ok = false;
  if (fstat(fd, &st) != 0) {
    *why = std::string("cannot stat: ") + std::strerror(errno);
  } else if (const char *bad = untrusted_file(st)) {
    *why = bad;
  } else if (st.st_size < static_cast<off_t>(kTrailerSize)) {
    *why = "too short to be sealed";
  } else if (!read_all(fd, static_cast<size_t>(st.st_size), &bytes)) {
    *why = "cannot read";
  } else {
    size_t object_size = bytes.size() - kTrailerSize;
    std::string_view object(bytes.data(), object_size);
    std::string_view seal(bytes.data() + object_size, kTrailerSize);
    if (seal != trailer(key, sha256(object), object_size))
      *why = seal.substr(0, sizeof kTrailerMagic) == std::string_view(kTrailerMagic, 16) &&
                     seal.substr(16, Sha256::kSize) == key
                 ? "its bytes do not match its recorded SHA-256"
                 : "not sealed by sicm for this source";
    else
      ok = true;
  }
  close(fd);
  return ok;
}

// Append the trailer for key to the compiler's output at path and make it
// private (the compiler creates it with the umask's permissions).
bool seal_object(const std::string &path, const Digest &key, std::string *why) {
  int fd = open(path.c_str(), O_RDWR | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) {
    *why = "cannot open " + path + ": " + std::strerror(errno);
    return false;
  }
  struct stat st;
  std::string bytes;
  bool ok = fstat(fd, &st) == 0 && S_ISREG(st.st_mode) &&
            read_all(fd, static_cast<size_t>(st.st_size), &bytes);
  if (ok) {
    std::string seal = trailer(key, sha256(bytes), bytes.size());
    ok = write_all(fd, seal.data(), seal.size(), st.st_size) && fchmod(fd, 0600) == 0;
  }
  if (!ok) *why = "cannot seal " + path + ": " + std::strerror(errno);
  return close(fd) == 0 && ok;
}

// ---- state ------------------------------------------------------------------

std::atomic<uint64_t> g_compiler_runs{0};
std::atomic<bool> g_warned_unsafe_dir{false};
std::mutex g_mutex;                                // the handle table and the fallback directory
std::unordered_map<std::string, void *> g_handles; // so path -> dlopen handle
std::string g_fallback_dir;                        // made on first need
char g_fallback_path[4096];                        // a copy for the exit handler

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

const char *const kFlags[] = {"-std=c11", "-O2", "-ffp-contract=off", "-fPIC", "-shared"};

// kFlags and, in a sanitized build, the sanitizer flags, so that the kernels
// a sanitized sicm loads are checked too (and cached apart from the others,
// since the flags are part of the key).
std::vector<std::string> compile_flags() {
  std::vector<std::string> flags(std::begin(kFlags), std::end(kFlags));
  for (std::string &f : sanitizer_flags())
    flags.push_back(std::move(f));
  return flags;
}

// What, besides the source, decides the object: the command line and the
// machine (a home directory may be shared by machines of several kinds).
std::string compiler_identity(const std::vector<std::string> &cc) {
  static const std::string machine = [] {
    struct utsname u;
    return uname(&u) == 0 ? std::string(u.sysname) + ' ' + u.machine : std::string("unknown");
  }();
  std::string id;
  for (const std::string &w : cc)
    id += w + ' ';
  for (const std::string &f : compile_flags())
    id += f + ' ';
  return id + '\0' + machine;
}

// mkdir -p with mode 0700 for what it creates; true if path is a directory at the end.
bool make_directories(const std::string &path) {
  struct stat st;
  if (stat(path.c_str(), &st) == 0) return S_ISDIR(st.st_mode);
  for (size_t i = 1; i <= path.size(); ++i) {
    if (i < path.size() && path[i] != '/') continue;
    std::string prefix = path.substr(0, i);
    if (mkdir(prefix.c_str(), 0700) != 0 && errno != EEXIST) return false;
  }
  return stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

// Why dir may not hold the cache, or "" if it may: it must belong to this
// user and be writable by no one else, or others could plant or swap entries.
std::string unsafe_directory(const std::string &dir) {
  struct stat st;
  if (stat(dir.c_str(), &st) != 0) return std::strerror(errno);
  if (st.st_uid != geteuid()) return "it is owned by uid " + std::to_string(st.st_uid);
  if (st.st_mode & (S_IWGRP | S_IWOTH)) {
    char mode[16];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    return std::string("it is writable by others (mode ") + mode + ")";
  }
  return "";
}

std::string fallback_dir() {
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

bool is_fallback_dir(const std::string &dir) {
  std::lock_guard<std::mutex> lock(g_mutex);
  return dir == g_fallback_dir;
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

// Compile source into dir/NAME.so (sealed for key, then renamed into place).
// The temporary files share a stem made unique by mkstemps, so concurrent
// compilations, even by processes with equal pids in different namespaces,
// never write the same file. False with a reason on failure.
bool compile_to(const std::string &dir, const std::string &name, const Digest &key,
                const std::string &source, const std::vector<std::string> &cc,
                const std::string &so, std::string *why_not) {
  std::string tmpl = dir + "/" + name + ".tmp.XXXXXX.c";
  std::vector<char> buf(tmpl.begin(), tmpl.end());
  buf.push_back('\0');
  int fd = mkstemps(buf.data(), 2);
  if (fd < 0) {
    *why_not = "cannot create a file in " + dir + ": " + std::strerror(errno);
    return false;
  }
  std::string src = buf.data(), stem = src.substr(0, src.size() - 2);
  std::string out = stem + ".so", log = stem + ".log";
  bool wrote = write_all(fd, source.data(), source.size(), 0);
  if (close(fd) != 0 || !wrote) {
    *why_not = "cannot write " + src + ": " + std::strerror(errno);
    std::remove(src.c_str());
    return false;
  }
  std::vector<std::string> argv = cc;
  std::vector<std::string> flags = compile_flags();
  argv.insert(argv.end(), flags.begin(), flags.end());
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
  else if (!seal_object(out, key, why_not))
    ok = false;
  else if (std::rename(out.c_str(), so.c_str()) != 0) {
    *why_not = "cannot rename " + out + " to " + so + ": " + std::strerror(errno);
    ok = false;
  }
  // Keep the source beside its object for whoever wants to read it.
  if (ok) std::rename(src.c_str(), (dir + "/" + name + ".c").c_str());
  std::remove(src.c_str());
  std::remove(out.c_str());
  std::remove(log.c_str());
  return ok;
}

void *loaded_handle(const std::string &so) {
  std::lock_guard<std::mutex> lock(g_mutex);
  auto h = g_handles.find(so);
  return h == g_handles.end() ? nullptr : h->second;
}

thread_local SrcLoc g_request_site; // see JitRequest
std::atomic<bool> g_limit_reached{false};

// Is there room for one more shared object under --max-compiled-kernels?
// When there is not, the first refusal says so on stderr, at the user's line.
bool may_load_another(std::string *why_not) {
  uint64_t limit = current_limits().max_compiled_kernels;
  size_t loaded;
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    loaded = g_handles.size();
  }
  if (limit == kUnlimited || loaded < limit) return true;
  g_limit_reached = true;
  *why_not = "the process has compiled " + std::to_string(loaded) +
             " distinct procedures (--max-compiled-kernels)";
  static std::atomic<bool> told{false};
  if (!told.exchange(true)) {
    SrcLoc loc = g_request_site.known()       ? g_request_site
                 : current_call_loc().known() ? current_call_loc()
                                              : current_toplevel_loc();
    std::fprintf(stderr,
                 "%s: note: the limit on compiled procedures that differ in structure "
                 "(--max-compiled-kernels=%llu) is reached; procedures not compiled yet are "
                 "interpreted from here on, more slowly\n",
                 loc_text(loc).c_str(), static_cast<unsigned long long>(limit));
  }
  return false;
}

// Verify the entry at so for key and dlopen it. Null with a reason in
// *error if it is not a good entry or does not load.
void *load_entry(const std::string &so, const Digest &key, std::string *error) {
  if (!verify_entry(so, key, error)) return nullptr;
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

std::vector<std::string> sanitizer_flags() {
#ifdef SICM_SANITIZE_FLAGS
  std::vector<std::string> words;
  std::istringstream in(SICM_SANITIZE_FLAGS);
  for (std::string w; in >> w;)
    words.push_back(w);
  return words;
#else
  return {};
#endif
}

bool jit_limit_reached() {
  return g_limit_reached;
}

uint64_t jit_compiler_runs() {
  return g_compiler_runs.load();
}

std::string jit_sha256(std::string_view text) {
  return hex(sha256(text));
}

std::string jit_hash(std::string_view text) {
  return hex(sha256(text).substr(0, 16));
}

std::string jit_cache_dir() {
  const char *xdg = std::getenv("XDG_CACHE_HOME");
  const char *home = std::getenv("HOME");
  std::string base;
  if (xdg && xdg[0] == '/')
    base = xdg;
  else if (home && home[0] == '/')
    base = std::string(home) + "/.cache";
  if (!base.empty() && make_directories(base + "/sicm")) {
    std::string dir = base + "/sicm";
    std::string unsafe = unsafe_directory(dir);
    if (unsafe.empty()) return dir;
    if (!g_warned_unsafe_dir.exchange(true))
      std::fprintf(stderr,
                   ";Note: not using the kernel cache %s: %s; kernels are compiled into a "
                   "temporary directory\n",
                   dir.c_str(), unsafe.c_str());
  }
  return fallback_dir();
}

JitRequest::JitRequest(SrcLoc where) : saved_(g_request_site) {
  g_request_site = where;
}

JitRequest::~JitRequest() {
  g_request_site = saved_;
}

void *jit_load(const std::string &c_source, const std::string &symbol, std::string *so_path,
               std::string *why_not) {
  std::string ignored;
  if (!why_not) why_not = &ignored;
  std::vector<std::string> cc = compiler_words();
  Digest key = sha256(c_source + '\0' + compiler_identity(cc));
  std::string name = hex(key.substr(0, 16));
  std::string dir = jit_cache_dir();
  if (dir.empty()) {
    *why_not = "no directory for compiled kernels (the cache and the temporary directory "
               "cannot be created)";
    return nullptr;
  }
  std::string so = dir + "/" + name + ".so";
  if (so_path) *so_path = so;
  void *handle = loaded_handle(so);
  std::string error;
  if (!handle && !may_load_another(why_not)) return nullptr;
  if (!handle) handle = load_entry(so, key, &error);
  if (!handle) { // not cached, or the entry is bad or does not load: build it anew, once
    if (!compile_to(dir, name, key, c_source, cc, so, why_not)) return nullptr;
    handle = load_entry(so, key, &error);
    if (!handle) {
      *why_not = "cannot load the compiled kernel " + so + ": " + error;
      return nullptr;
    }
    if (is_fallback_dir(dir)) { // loaded: the mapping outlives the files
      std::remove(so.c_str());
      std::remove((dir + "/" + name + ".c").c_str());
    }
  }
  void *address = dlsym(handle, symbol.c_str());
  if (!address) *why_not = "the compiled kernel " + so + " has no symbol " + symbol;
  return address;
}

} // namespace sicm
