// The last pass of `sicm build`: the C of a residual program (see
// driver/pipeline.cpp) compiled by the system C compiler ($CC or cc) against
// the runtime library, found beside the sicm executable (build tree:
// build/libsicmrt.a and runtime/include; installed: PREFIX/lib and
// PREFIX/include).
#pragma once

#include <string>

#include "driver/pipeline.hpp"

namespace sicm {

// Compile `c` into the executable options.output (with options.opt_level,
// options.mpi, options.keep_c). Returns the exit status (0 on success); a
// missing runtime or a failing C compiler is reported here.
int compile_executable(const std::string &c, const BuildOptions &options);

// Can the executable be written at options.output? 0 if it seems so; else
// one line on stderr naming the path and the system's reason, and the exit
// status. Checked before any work, so a mistyped -o costs no compilation.
int check_output_writable(const BuildOptions &options);

} // namespace sicm
