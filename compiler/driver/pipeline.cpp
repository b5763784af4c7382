// The pipeline: each command of sicm as its sequence of passes, each pass
// one call into the file that does it.
//
// sicm run FILE                                               run_program
//   read the source          syntax/reader.cpp     (text -> data with positions)
//   then, form by form       eval/interp.cpp       run_source:
//     analyze                eval/analyze.cpp      (special forms -> Nodes)
//     evaluate               eval/eval.cpp         (Nodes -> values; symbolic work in
//                                                   algebra/ and cas/)
//     numerical primitives   builtins/numerics.cpp (a procedure handed to one is traced,
//                                                   codegen/trace.cpp, emitted,
//                                                   codegen/emit_c.cpp, and loaded,
//                                                   codegen/jit.cpp; bisect's function
//                                                   through pe/for_run.cpp)
//     print                  print/printer.cpp
//
// sicm build FILE                                             build_program
//   read the source          syntax/reader.cpp
//   partially evaluate       pe/build_mode.cpp     (a BuildSession: the program runs with
//                                                   build mode on; numerical work and what
//                                                   depends on it becomes a residual
//                                                   program, codegen/residual.hpp; an `if`
//                                                   on a run-time value is pe/branches.cpp's
//                                                   hook_branch, a loop pe/loops.cpp)
//   emit C                   codegen/residual_emit.cpp
//   compile                  driver/build_exe.cpp  (cc against libsicmrt.a)
// sicm emit-c FILE prints the C instead of compiling it; sicm report and
// --report count its operations (codegen/kernel_report.cpp); --dump=PASS
// prints one intermediate form and stops (kDumpPasses).
//
// sicm emit-kernels FILE                                      emit_kernels
//   sicm run, quietly, listening for the kernels the JIT loads.
#include "driver/pipeline.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "base/srcloc.hpp"
#include "base/temporary_files.hpp"
#include "builtins/effects_used.hpp"
#include "builtins/parameter.hpp"
#include "builtins/plot.hpp"
#include "codegen/emit_c.hpp"
#include "codegen/kernel.hpp"
#include "codegen/kernel_report.hpp"
#include "codegen/residual_check.hpp"
#include "codegen/residual_dump.hpp"
#include "codegen/residual_emit.hpp"
#include "driver/build_exe.hpp"
#include "eval/analyze.hpp"
#include "eval/analyzed_dump.hpp"
#include "eval/core.hpp"
#include "eval/interp.hpp"
#include "pe/build.hpp"
#include "syntax/reader.hpp"

namespace sicm {

namespace {

constexpr int kExitNoInput = 66;   // EX_NOINPUT
constexpr int kExitCantCreat = 73; // EX_CANTCREAT
constexpr int kExitUsage = 64;     // EX_USAGE: a --param or --fix of no parameter

// Register the file's text as a source; false (after a message) if it cannot be read.
bool read_source(const std::string &path, uint32_t *file) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "sicm: cannot open %s: %s\n", path.c_str(), std::strerror(errno));
    return false;
  }
  std::ostringstream text;
  text << in.rdbuf();
  *file = register_source(path, text.str());
  return true;
}

std::string base_name(const std::string &path) {
  size_t slash = path.rfind('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// sicm emit-kernels: the C source of each kernel compiled, once each.
std::string g_emitted;

void collect_kernel(const Kernel *k) {
  if (g_emitted.find(k->c_source) != std::string::npos) return; // the same kernel again
  g_emitted += "/* ---- kernel " + k->c_name + " ---- */\n";
  if (!k->params.empty()) { // the values its p[] holds here (codegen/kernel.hpp)
    g_emitted += "/* p[] = {";
    for (size_t j = 0; j < k->params.size(); ++j)
      g_emitted += (j ? ", " : "") + c_double_literal(k->params[j]);
    g_emitted += "} */\n";
  }
  g_emitted += k->c_source + "\n";
}

// --param and --fix must name parameters the program declared: a
// misspelt name would otherwise be ignored in silence.
int check_parameter_options() {
  std::string error = undeclared_parameter_error();
  if (error.empty()) return 0;
  flush_output();
  std::fprintf(stderr, "sicm: error: %s\n", error.c_str());
  return kExitUsage;
}

} // namespace

int run_program(const std::string &path) {
  uint32_t file;
  if (!read_source(path, &file)) return kExitNoInput;
  run_source(file);
  return check_parameter_options();
}

int run_quietly(const std::string &path) {
  std::string pattern = temporary_directory() + "/sicm-emit-XXXXXX";
  std::vector<char> dir(pattern.begin(), pattern.end());
  dir.push_back('\0');
  bool have_dir = mkdtemp(dir.data()) != nullptr;
  if (have_dir) set_plot_directory(dir.data());
  struct RemoveDir {
    const char *path;
    ~RemoveDir() {
      std::error_code ignored;
      if (path) std::filesystem::remove_all(path, ignored);
    }
  } remove_dir{have_dir ? dir.data() : nullptr};
  std::fflush(stdout);
  int saved = dup(1);
  int null_fd = open("/dev/null", O_WRONLY);
  if (saved >= 0 && null_fd >= 0) dup2(null_fd, 1);
  int status = 0;
  try {
    status = run_program(path);
  } catch (...) {
    flush_output();
    if (saved >= 0) dup2(saved, 1);
    throw;
  }
  flush_output();
  if (saved >= 0) dup2(saved, 1);
  if (null_fd >= 0) close(null_fd);
  return status;
}

int emit_kernels(const std::string &path) {
  set_kernel_listener(collect_kernel);
  int status = run_quietly(path);
  if (status == 0) {
    if (g_emitted.empty()) std::fputs("/* this program compiles no kernels */\n", stdout);
    std::fputs(g_emitted.c_str(), stdout);
  }
  return status;
}

int build_program(const BuildOptions &o) {
  uint32_t file;
  if (!read_source(o.input, &file)) return kExitNoInput;
  if (o.dump.empty() && !o.emit_only && !o.report_only)
    if (int status = check_output_writable(o)) return status;
  if (o.dump == "analyzed") {
    for (const ReadForm &f : read_all(file))
      std::printf("%s\n", dump_node(analyze_form(f.datum, f.loc, nullptr)).c_str());
    return 0;
  }

  BuildSession build;
  ResidualProgram &program = build.program();
  program.source_name = base_name(o.input);
  try {
    run_source(file);
  } catch (const Error &e) {
    // An error of the program itself, met where it is certain to happen
    // when the program runs: the executable prints what comes before it and
    // then fails with it, as sicm run does. Anything else (cannot compile,
    // a limit, an error inside code left for run time) fails the build.
    if (e.kind != ErrorKind::Runtime || e.cause != ErrorCause::Other || !e.at_top_level) throw;
    build.fail_here(e);
    std::fprintf(stderr, "%s: warning: the program fails here when it runs: %s\n",
                 loc_text(e.loc).c_str(), BuildSession::described(e.what()).c_str());
  }
  check_residual(program, "partial evaluation");
  if (int status = check_parameter_options()) return status;
  if (o.dump == "residual") {
    std::fputs(dump_residual(program).c_str(), stdout);
    return 0;
  }

  std::string c = emit_residual_program(program);
  if (o.dump == "kernels") {
    std::fputs(report_table(report_kernels(program, c), used_effects()).c_str(), stdout);
    return 0;
  }
  if (o.dump == "c") {
    std::fwrite(c.data(), 1, c.size(), stdout);
    return 0;
  }
  if (!o.report_path.empty()) {
    std::vector<KernelReport> kernels = report_kernels(program, c);
    std::ofstream json(o.report_path, std::ios::binary);
    json << report_json(kernels, used_effects());
    if (!json) {
      std::fprintf(stderr, "sicm: error: cannot write %s\n", o.report_path.c_str());
      return kExitCantCreat;
    }
    if (o.report_only) {
      std::fputs(report_table(kernels, used_effects()).c_str(), stdout);
      std::printf("wrote %s\n", o.report_path.c_str());
      return 0;
    }
  }
  if (o.emit_only) {
    std::fwrite(c.data(), 1, c.size(), stdout);
    return 0;
  }
  return compile_executable(c, o);
}

} // namespace sicm
