// `sicm build` and `sicm emit-c`: a program compiled to C, then to an executable.
//
// The program runs once in build mode (pe/build.hpp), which records its
// residual program; that is emitted as C (codegen/residual_emit.hpp) and
// compiled with the system C compiler ($CC or cc) against the runtime
// library, found beside the sicm executable (build tree: build/libsicmrt.a
// and runtime/include; installed: PREFIX/lib and PREFIX/include).
#pragma once

#include <string>

namespace sicm {

struct BuildOptions {
  std::string input;
  std::string output; // the executable; empty for emit-c
  std::string opt_level = "-O2";
  bool keep_c = false;      // leave OUTPUT.c beside the executable
  std::string dump;         // --dump=PASS: print that intermediate form instead (kDumpPasses)
  bool mpi = false;         // compile with mpicc against libsicmrt_mpi.a (see sicm_mpi_start)
  bool emit_only = false;   // print the C on stdout instead of compiling
  bool report_only = false; // sicm report: print the kernels' table, write report_path
  std::string report_path;  // where to write the kernels' JSON (kernel_report.hpp); empty: none
};

// The intermediate forms --dump can print, in pipeline order: the analyzed
// top-level forms (eval/analyzed_dump.hpp), the residual program
// (codegen/residual_dump.hpp), the kernels' report table
// (codegen/kernel_report.hpp), the C.
inline constexpr const char *kDumpPasses[] = {"analyzed", "residual", "kernels", "c"};

// Returns the process exit status (0 on success). Errors in the program
// propagate as Error (reported by the caller); a failing C compiler is
// reported here.
int build_program(const BuildOptions &options);

} // namespace sicm
