// The JIT: C source to a loaded shared object through the system C compiler, cached by content hash.
//
// The compiler is $CC (split on blanks) or `cc`, run without a shell as
//   CC -std=c11 -O2 -fPIC -shared -o OUT.so SRC.c -lm
// (no -ffast-math: kernels keep IEEE semantics). Objects are cached in
// $XDG_CACHE_HOME/sicm, else ~/.cache/sicm, else a private temporary
// directory, under a 128-bit hash of the source and the command line, so an
// unchanged kernel is compiled once per machine. Files are written under
// temporary names and renamed into place: concurrent runs never load half a
// file. Loaded objects stay loaded for the life of the process.
#pragma once

#include <cstdint>
#include <string>

namespace sicm {

// Compile (or find in the cache) `c_source`, load it and return the address
// of `symbol` in it. On failure returns null and a one-line reason (with the
// start of the compiler's diagnostics) in *why_not. *so_path, if not null,
// receives the shared object's path.
void *jit_load(const std::string &c_source, const std::string &symbol, std::string *so_path,
               std::string *why_not);

// How many times this process has started the C compiler (tests use it to
// see that the cache works).
uint64_t jit_compiler_runs();

// The cache directory jit_load would use now (created if missing).
std::string jit_cache_dir();

// The 128-bit content hash the cache uses, as 32 hex digits.
std::string jit_hash(const std::string &text);

} // namespace sicm
