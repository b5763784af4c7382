// The sicm command: the command line, the evaluator thread, and the
// command dispatched to its pipeline (driver/pipeline.cpp) or the REPL.
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "base/error.hpp"
#include "base/limits.hpp"
#include "bench/work_precision.hpp"
#include "builtins/integration_sites.hpp"
#include "builtins/numerics_defaults.hpp"
#include "builtins/parameter.hpp"
#include "builtins/plot.hpp"
#include "codegen/kernel.hpp"
#include "driver/init.hpp"
#include "driver/jupyter_session.hpp"
#include "driver/pipeline.hpp"
#include "driver/repl.hpp"
#include "driver/run_check.hpp"
#include "eval/core.hpp"
#include "eval/interp.hpp"
#include "eval/procedure.hpp"
#include "sicm/runtime.h"

namespace {

constexpr int kExitUsage = 64; // EX_USAGE

// The evaluator runs on a thread with a large stack so that deep (non-tail)
// recursion in user programs works as it does in MIT Scheme; the stack guard
// turns recursion beyond it into a clean error.
constexpr size_t kEvalStackBytes = size_t(256) << 20;  // reserved; pages are touched as used
constexpr size_t kStackGuardMargin = size_t(16) << 20; // kept free for primitives

// Under AddressSanitizer the evaluator's stack is at most 64 MiB: ASan clears
// the poison of the frames an exception unwinds only when the throw is
// within 64 MiB of the thread's stack top (google/sanitizers#189); a deeper
// throw leaves stale poison behind, and later calls at those depths get
// false reports. A sanitized sicm so stops plain recursion at about 20,000
// levels instead of a million.
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SICM_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(SICM_ASAN)
constexpr size_t kMaxEvalStackBytes = size_t(64) << 20;
#else
constexpr size_t kMaxEvalStackBytes = SIZE_MAX;
#endif

const char kUsage[] =
    "usage: sicm run FILE [--plot-dir DIR] [--param NAME=VALUE ...] [--stats]\n"
    "                            evaluate a program, printing each top-level value;\n"
    "                            plots (frame ...) are written to DIR (default .);\n"
    "                            --param sets (parameter 'NAME default); --stats\n"
    "                            prints what each integration cost on stderr (so\n"
    "                            do built programs given --stats)\n"
    "       sicm build FILE [-o EXE] [-O0|-O1|-O2|-O3] [--keep-c] [--report[=PATH]]\n"
    "                  [--fix NAME=VALUE ...] [--mpi] [--dump=PASS]\n"
    "                            compile to an executable (default: FILE without\n"
    "                            .sicm); --keep-c leaves the C as EXE.c; --mpi links\n"
    "                            Open MPI: under mpirun, parallel-map's members are\n"
    "                            spread over the ranks; --dump=PASS prints one\n"
    "                            intermediate form instead (analyzed, residual,\n"
    "                            kernels, c; also for emit-c)\n"
    "                            --report[=PATH] also writes what each kernel\n"
    "                            computes, as JSON (default PATH: EXE.report.json);\n"
    "                            --fix makes (parameter 'NAME ...) the constant VALUE\n"
    "                            (also for emit-c and report)\n"
    "       sicm report FILE [--report=PATH]\n"
    "                            print what each kernel of the built program computes\n"
    "                            (op counts of its C) and write the JSON (default:\n"
    "                            FILE without .sicm, .report.json)\n"
    "       sicm emit-c FILE     print the C that sicm build compiles\n"
    "       sicm emit-kernels FILE\n"
    "                            run the program quietly and print the C of every\n"
    "                            kernel sicm run compiles (state derivatives, ...)\n"
    "       sicm bench FILE [--out DIR] [--methods M1,M2,...] [--tolerances FROM:TO]\n"
    "                  [--repeats N]\n"
    "                            run the program quietly, then each integration it\n"
    "                            performs (first call per site) with every method and\n"
    "                            tolerance: DIR/work-precision.tsv and .svg (default\n"
    "                            DIR: FILE-bench; tolerances 1e-3:1e-14 by decades)\n"
    "       sicm repl            interactive read-eval-print loop\n"
    "       sicm repl --kernel [--plot-dir DIR]\n"
    "                            the session of a Jupyter kernel: requests on stdin,\n"
    "                            JSON replies on stdout (driver/jupyter_protocol.hpp)\n"
    "       sicm --version\n"
    "run, build, emit-c, emit-kernels and repl also take the limit flags\n"
    "--max-steps, --max-memory, --max-expression-nodes, --max-recursion-depth,\n"
    "--max-residual-size, and for build the unroll limits --max-unrolled-elements\n"
    "and --max-unrolled-iterations (sicm --help lists their defaults)\n";

// The program `sicm build` (or emit-c, report) is compiling, for the note
// of a "cannot compile" error (driver/run_check.hpp); empty otherwise.
std::string g_build_input;
// How long `sicm run` may run a program the build refused before the note
// says only that it ran that long without failing.
constexpr double kRunCheckSeconds = 10;

struct Job {
  std::vector<std::string> args;
  sicm::Limits limits; // as given on the command line; 0 = the default
  bool compile_time = false;
  size_t stack_bytes = kEvalStackBytes;
  int status = 0;
};

// FILE.sicm without its extension (what a program's outputs are named
// after); any other name unchanged.
std::string without_sicm_extension(const std::string &file) {
  const std::string ext = ".sicm";
  if (file.size() > ext.size() && file.compare(file.size() - ext.size(), ext.size(), ext) == 0)
    return file.substr(0, file.size() - ext.size());
  return file;
}

// sicm bench FILE [--out DIR] [--methods M1,M2,...] [--tolerances FROM:TO] [--repeats N]
int bench(const std::vector<std::string> &args) {
  sicm::BenchOptions o;
  std::string file;
  for (size_t i = 1; i < args.size(); ++i) {
    const std::string &a = args[i];
    bool has_value = i + 1 < args.size();
    if (a == "--out" && has_value) {
      o.out_dir = args[++i];
    } else if (a == "--methods" && has_value) {
      std::stringstream list(args[++i]);
      for (std::string m; std::getline(list, m, ',');) {
        if (!sicm::integrator_named(m)) {
          std::fprintf(stderr, "sicm bench: --methods: no integrator is named %s\n", m.c_str());
          return kExitUsage;
        }
        o.methods.push_back(m);
      }
    } else if (a == "--tolerances" && has_value) {
      const std::string &range = args[++i];
      size_t colon = range.find(':');
      char *end1 = nullptr, *end2 = nullptr;
      double from = colon == std::string::npos ? 0 : std::strtod(range.c_str(), &end1);
      double to = colon == std::string::npos ? 0 : std::strtod(range.c_str() + colon + 1, &end2);
      if (colon == std::string::npos || end1 != range.c_str() + colon || *end2 != '\0' ||
          !(from > 0) || !(to > 0) || to > from) {
        std::fprintf(stderr, "sicm bench: --tolerances %s: want FROM:TO, FROM >= TO > 0\n",
                     range.c_str());
        return kExitUsage;
      }
      o.tolerance_from = from, o.tolerance_to = to;
    } else if (a == "--repeats" && has_value) {
      char *end = nullptr;
      long n = std::strtol(args[++i].c_str(), &end, 10);
      if (*end != '\0' || n < 1 || n > 1000) {
        std::fprintf(stderr, "sicm bench: --repeats %s: want a count from 1 to 1000\n",
                     args[i].c_str());
        return kExitUsage;
      }
      o.repeats = static_cast<int>(n);
    } else if (file.empty() && a.rfind("--", 0) != 0) {
      file = a;
    } else {
      std::fputs(kUsage, stderr);
      return kExitUsage;
    }
  }
  if (file.empty()) {
    std::fputs(kUsage, stderr);
    return kExitUsage;
  }
  if (o.out_dir.empty()) o.out_dir = without_sicm_extension(file) + "-bench";
  sicm::record_integration_sites(true);
  int status = sicm::run_quietly(file);
  sicm::record_integration_sites(false);
  if (status != 0) return status;
  return sicm::run_work_precision(o);
}

int dispatch(const std::vector<std::string> &args) {
  if (!args.empty() && args[0] == "repl" && args.size() > 1) {
    sicm::JupyterOptions k;
    bool kernel = false;
    for (size_t i = 1; i < args.size(); ++i) {
      if (args[i] == "--kernel") {
        kernel = true;
      } else if (args[i] == "--plot-dir" && i + 1 < args.size()) {
        k.plot_dir = args[++i];
      } else {
        std::fputs(kUsage, stderr);
        return kExitUsage;
      }
    }
    if (!kernel) {
      std::fputs(kUsage, stderr);
      return kExitUsage;
    }
    return sicm::run_jupyter_session(k);
  }
  if (args.empty() || args[0] == "repl") {
    sicm::ReplOptions opts;
    opts.interactive = isatty(0) && isatty(1);
    return sicm::run_repl(opts);
  }
  const std::string &cmd = args[0];
  if (cmd == "--version") {
    std::printf("sicm 0.1\n");
    return 0;
  }
  if (cmd == "--help" || cmd == "-h") {
    std::fputs(kUsage, stdout);
    std::fputs(("\n" + sicm::limits_usage()).c_str(), stdout);
    return 0;
  }
  if (cmd == "bench") return bench(args);
  if (cmd == "emit-kernels") {
    if (args.size() != 2) {
      std::fputs(kUsage, stderr);
      return kExitUsage;
    }
    return sicm::emit_kernels(args[1]);
  }
  if (cmd == "build" || cmd == "emit-c" || cmd == "report") {
    sicm::BuildOptions o;
    o.emit_only = cmd == "emit-c";
    o.report_only = cmd == "report";
    bool want_report = o.report_only;
    for (size_t i = 1; i < args.size(); ++i) {
      const std::string &a = args[i];
      std::string why;
      if (a == "--fix" && i + 1 < args.size()) {
        if (!sicm::fix_parameter_option(args[++i], &why)) {
          std::fprintf(stderr, "sicm: %s\n", why.c_str());
          return kExitUsage;
        }
      } else if (a == "--report" && cmd == "build") {
        want_report = true;
      } else if (a.rfind("--report=", 0) == 0 && cmd != "emit-c" && a.size() > 9) {
        want_report = true;
        o.report_path = a.substr(9);
      } else if (a == "-o" && i + 1 < args.size() && cmd == "build") {
        o.output = args[++i];
      } else if (cmd == "build" && (a == "-O0" || a == "-O1" || a == "-O2" || a == "-O3")) {
        o.opt_level = a;
      } else if (a == "--keep-c" && cmd == "build") {
        o.keep_c = true;
      } else if (a == "--mpi" && cmd == "build") {
        o.mpi = true;
      } else if (a.rfind("--dump=", 0) == 0 && (cmd == "build" || cmd == "emit-c")) {
        o.dump = a.substr(7);
        bool known = false;
        for (const char *pass : sicm::kDumpPasses)
          known = known || o.dump == pass;
        if (!known) {
          std::fprintf(stderr, "sicm: --dump=%s: not one of analyzed, residual, kernels, c\n",
                       o.dump.c_str());
          return kExitUsage;
        }
      } else if (o.input.empty() && a.rfind("-", 0) != 0) {
        o.input = a;
      } else {
        std::fputs(kUsage, stderr);
        return kExitUsage;
      }
    }
    if (o.input.empty()) {
      std::fputs(kUsage, stderr);
      return kExitUsage;
    }
    if (o.output.empty()) {
      o.output = without_sicm_extension(o.input);
      if (o.output == o.input) o.output += ".out";
    }
    if (want_report && o.report_path.empty()) o.report_path = o.output + ".report.json";
    g_build_input = o.input;
    return sicm::build_program(o);
  }
  if (cmd == "run") {
    std::string file;
    for (size_t i = 1; i < args.size(); ++i) {
      std::string why;
      if (args[i] == "--plot-dir" && i + 1 < args.size()) {
        sicm::set_plot_directory(args[++i]);
      } else if (args[i] == "--stats") {
        sicm_stats_enable();
      } else if (args[i] == "--param" && i + 1 < args.size()) {
        if (!sicm::set_parameter_option(args[++i], &why)) {
          std::fprintf(stderr, "sicm: %s\n", why.c_str());
          return kExitUsage;
        }
      } else if (file.empty() && args[i].rfind("--", 0) != 0) {
        file = args[i];
      } else {
        std::fputs(kUsage, stderr);
        return kExitUsage;
      }
    }
    if (file.empty()) {
      std::fputs(kUsage, stderr);
      return kExitUsage;
    }
    return sicm::run_program(file);
  }
  std::fprintf(stderr, "sicm: unknown command '%s'\n%s", cmd.c_str(), kUsage);
  return kExitUsage;
}

void *evaluator_thread(void *arg) {
  Job *job = static_cast<Job *>(arg);
  char base;
  sicm::set_stack_limit(&base, job->stack_bytes - kStackGuardMargin);
  try {
    sicm::init_interpreter();
    // The library loaded, the user's limits apply.
    sicm::set_stack_limit(&base, std::min(job->stack_bytes - kStackGuardMargin,
                                          sicm::recursion_stack_bytes(job->limits)));
    sicm::set_limits(job->limits, job->compile_time);
    job->status = dispatch(job->args);
  } catch (const sicm::Error &e) {
    sicm::flush_output();
    sicm::Error shown = sicm::as_users_error(e);
    // A program the build refuses: say what sicm run does with it.
    if (e.cause == sicm::ErrorCause::CannotCompile && !g_build_input.empty())
      if (std::string does = sicm::what_sicm_run_does(g_build_input, kRunCheckSeconds);
          !does.empty())
        shown.note += (shown.note.empty() ? "" : "; ") + does;
    sicm::report_error(stderr, shown);
    job->status = e.exit_code();
  } catch (const std::bad_alloc &) {
    sicm::flush_output();
    std::fprintf(stderr, "sicm: error: out of memory\n");
    job->status = sicm::kExitRuntimeError;
  }
  sicm::flush_output();
  return nullptr;
}

} // namespace

int main(int argc, char **argv) {
  GC_INIT();
  Job job;
  job.args.assign(argv + 1, argv + argc);
  std::string bad_limit;
  if (!sicm::take_limit_flags(job.args, &job.limits, &bad_limit)) {
    std::fprintf(stderr, "sicm: %s\n%s", bad_limit.c_str(), kUsage);
    return kExitUsage;
  }
  job.compile_time = !job.args.empty() && (job.args[0] == "build" || job.args[0] == "emit-c");
  job.stack_bytes = std::min(sicm::evaluator_stack_bytes(job.limits), // at least kEvalStackBytes
                             kMaxEvalStackBytes);
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  pthread_attr_setstacksize(&attr, job.stack_bytes);
  pthread_t thread;
  if (pthread_create(&thread, &attr, evaluator_thread, &job) != 0) {
    std::fprintf(stderr, "sicm: cannot start the evaluator thread (a stack of %zu MiB)\n",
                 job.stack_bytes >> 20);
    return 1;
  }
  pthread_join(thread, nullptr);
  sicm_stats_print(stderr); // --stats: after the run, whether it succeeded or failed
  return job.status;
}
