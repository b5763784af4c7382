// The pipeline: each command of sicm as its sequence of passes (see
// pipeline.cpp, which names the file of every pass).
#pragma once

#include <string>

namespace sicm {

// sicm run FILE: evaluate the program, printing what it prints. Returns the
// exit status; errors in the program propagate as Error.
int run_program(const std::string &path);

// The program run with its output discarded and its plots in a scratch
// directory, removed afterwards (sicm emit-kernels, sicm bench).
int run_quietly(const std::string &path);

// sicm emit-kernels FILE: run quietly, then print the C of every kernel compiled.
int emit_kernels(const std::string &path);

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

// sicm build, emit-c and report: the program partially evaluated into a
// residual program, written as C, compiled. Returns the exit status; errors
// in the program propagate as Error, a failing C compiler is reported here.
int build_program(const BuildOptions &options);

} // namespace sicm
