// The JIT: C source to a loaded shared object by the system C compiler, cached by content hash.
//
// The compiler is $CC (split on blanks) or `cc`, run without a shell as
//   CC -std=c11 -O2 -ffp-contract=off -fPIC -shared [SANITIZER FLAGS] -o OUT.so SRC.c -lm
// (no -ffast-math: kernels keep IEEE semantics; no fused multiply-adds, so
// the kernel interpreter, codegen/kernel_interpreter.hpp, gives their bits). Objects are cached in
// $XDG_CACHE_HOME/sicm, else ~/.cache/sicm, else a private temporary
// directory, as KEY.so where KEY is the SHA-256 of the source, the compiler
// command and the machine, so an unchanged kernel is compiled once per
// machine. The cache is trusted only as far as it is checked:
//   - the directory must be owned by this user and writable by no one else
//     (else the private temporary directory is used, with a note on stderr);
//   - a KEY.so is loaded only if it is a regular file (not a symbolic link)
//     owned by this user, writable by no one else, and ends in a trailer that
//     this code appended when it built the object: the full key and the
//     SHA-256 of every byte before the trailer, both of which must match;
//   - anything else (missing, truncated, corrupt, planted, written by an older
//     sicm, or refused by dlopen) is rebuilt once, then loaded.
// Objects are compiled under unique temporary names and renamed into place,
// so concurrent runs never see half a file. Loaded objects stay loaded for
// the life of the process. docs/reliability.md gives the reasons.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "base/srcloc.hpp"

namespace sicm {

// While a JitRequest lives (on this thread), a shared object that
// --max-compiled-kernels refuses is reported at `where`: the user's line
// that asked for the compiled procedure, taken before tracing it moves the
// evaluator into the procedure (or the library).
class JitRequest {
public:
  explicit JitRequest(SrcLoc where);
  ~JitRequest();
  JitRequest(const JitRequest &) = delete;
  JitRequest &operator=(const JitRequest &) = delete;

private:
  SrcLoc saved_;
};

// Compile (or find in the cache) `c_source`, load it and return the address
// of `symbol` in it. On failure returns null and a one-line reason (with the
// start of the compiler's diagnostics) in *why_not. *so_path, if not null,
// receives the shared object's path. Thread-safe.
void *jit_load(const std::string &c_source, const std::string &symbol, std::string *so_path,
               std::string *why_not);

// The sanitizer flags sicm itself was built with (SANITIZE=1 in the
// Makefile defines SICM_SANITIZE_FLAGS), else none. Generated C is compiled
// with them too: a sanitized process should load checked kernels, and an
// executable linked with a sanitized libsicmrt.a needs the sanitizer runtimes.
std::vector<std::string> sanitizer_flags();

// How many times this process has started the C compiler (tests use it to
// see that the cache works).
uint64_t jit_compiler_runs();

// Has --max-compiled-kernels refused a procedure in this process?
bool jit_limit_reached();

// The cache directory jit_load would use now (created if missing).
std::string jit_cache_dir();

// A 128-bit content hash (the first half of the SHA-256), as 32 hex digits.
std::string jit_hash(std::string_view text);

// The SHA-256 of text (FIPS 180-4), as 64 hex digits.
std::string jit_sha256(std::string_view text);

} // namespace sicm
