// Fuzz target: the evaluator. Any bytes are run as a program, as `sicm run` runs a file.
//
// Property: a program never crashes sicm, trips a sanitizer or escapes with
// anything but a sicm::Error (or std::bad_alloc, which `sicm` reports as
// "out of memory"): every error a program can cause is a reported error.
//
// Bounds, until the evaluator has named limits of its own:
//   - inputs longer than kMaxInput bytes are rejected;
//   - a run is cancelled after kDeadlineMs of wall time (FUZZ_EVAL_MS
//     overrides): a watchdog thread lowers the evaluator's stack guard, so
//     the next procedure call raises "Aborting!: maximum recursion depth
//     exceeded", which unwinds like any error; a primitive that loops
//     without calling back into the evaluator (a huge make-list, an expt of
//     bignums) is caught by libFuzzer's -timeout and -rss_limit_mb instead;
//   - the primitives in kExcluded are rebound to one that raises an error,
//     so a program cannot reach them even through a computed name or the
//     library: they start the C compiler (compile-procedure, and evolve and
//     state-advancer through their kernels), write files (plots), end the
//     process (exit), or depend on the clock or a random state (runtime,
//     real-time, random), which would make runs irreproducible;
//   - output is discarded (set_output_hook), and SICM_INTERPRET=1 keeps the
//     C compiler out (kernels, if any, run in the kernel interpreter).
// Between inputs the global bindings are restored to what they were after
// start-up (redefinitions undone, definitions of the names the program
// mentions removed), so an input that redefines `car` does not change how
// later inputs run. Not restored: a definition of a name the program
// computes (string->symbol and eval), and state inside values (a set-car! on
// a list the library holds). Inputs the reader rejects are skipped.
#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <new>
#include <string>
#include <thread>
#include <unordered_set>
#include <vector>

#include "base/error.hpp"
#include "base/primitive.hpp"
#include "base/srcloc.hpp"
#include "builtins/plot.hpp"
#include "common.hpp"
#include "driver/init.hpp"
#include "eval/core.hpp"
#include "eval/interp.hpp"
#include "eval/procedure.hpp"
#include "syntax/reader.hpp"

using namespace sicm;

namespace {

constexpr size_t kMaxInput = 2048;
constexpr int kDeadlineMs = 1000;

const char *const kExcluded[] = {
    "compile-procedure", "evolve",         "state-advancer", "frame",          "plot-point",
    "plot-line",         "graphics-close", "graphics-clear", "exit",           "%exit",
    "runtime",           "real-time",      "random",         "emergency-exit",
};

Value excluded_primitive(Value *, int) {
  runtime_error(current_call_loc(), "this primitive is excluded when fuzzing the evaluator");
}

void discard_output(std::string_view) {}

// ---- the global environment as it was after start-up ----

std::vector<Symbol *> g_saved_symbols;
gcvec<Value> g_saved_values; // g_saved_values[i] is g_saved_symbols[i]'s binding
std::unordered_set<Symbol *> g_saved_set;

void snapshot_globals() {
  for (const std::string &name : global_names()) {
    Symbol *s = intern(name).symbol();
    g_saved_symbols.push_back(s);
    g_saved_values.push_back(s->global);
    g_saved_set.insert(s);
  }
}

// The symbols a datum mentions, which include every name the program can
// define (except names it computes, as with string->symbol and eval).
void collect_symbols(Value d, std::vector<Symbol *> &out, int depth = 0) {
  if (depth > kMaxReadDepth) return;
  if (d.is(Tag::Symbol)) {
    if (!g_saved_set.count(d.symbol())) out.push_back(d.symbol());
  } else if (d.is(Tag::Pair)) {
    for (; d.is(Tag::Pair); d = d.pair()->cdr)
      collect_symbols(d.pair()->car, out, depth + 1);
    collect_symbols(d, out, depth + 1);
  } else if (d.is(Tag::Vector)) {
    for (size_t i = 0; i < d.vector()->len; ++i)
      collect_symbols(d.vector()->items[i], out, depth + 1);
  }
}

// Undo the program's definitions and assignments of globals: the names it
// mentions that were unbound at start-up are unbound again, and every name
// bound at start-up gets its binding back. (Listing every bound name after
// each run would be exact, but it costs more than most runs.)
void restore_globals(const std::vector<Symbol *> &mentioned) {
  for (Symbol *s : mentioned) {
    s->bound = false;
    s->global = Value();
  }
  for (size_t i = 0; i < g_saved_symbols.size(); ++i) {
    g_saved_symbols[i]->global = g_saved_values[i];
    g_saved_symbols[i]->bound = true;
  }
}

// ---- the watchdog ----

// Never destroyed: the watchdog waits on them until the process ends, and
// destroying a condition variable that a thread waits on blocks exit.
std::mutex &g_mutex = *new std::mutex;
std::condition_variable &g_wake = *new std::condition_variable;
uint64_t g_generation = 0; // odd while a run is in progress
std::chrono::steady_clock::time_point g_deadline;
int g_deadline_ms = kDeadlineMs;
std::atomic<unsigned long> g_cancelled{0};
unsigned long g_runs = 0;
double g_run_seconds = 0;
std::chrono::steady_clock::time_point g_run_start;

void watchdog() {
  sigset_t alarm; // libFuzzer's -timeout must reach the fuzzing thread, not this one
  sigemptyset(&alarm);
  sigaddset(&alarm, SIGALRM);
  pthread_sigmask(SIG_BLOCK, &alarm, nullptr);
  std::unique_lock<std::mutex> lock(g_mutex);
  for (;;) {
    if (g_generation % 2 == 0) {
      g_wake.wait(lock);
      continue;
    }
    uint64_t gen = g_generation;
    if (g_wake.wait_until(lock, g_deadline) == std::cv_status::timeout && g_generation == gen) {
      // Every address is below this limit: the next check_stack raises.
      set_stack_limit(reinterpret_cast<char *>(UINTPTR_MAX), 0);
      ++g_cancelled;
      g_wake.wait(lock, [gen] { return g_generation != gen; });
    }
  }
}

// What the runs did, printed at exit (for docs/reliability.md).
void print_stats() {
  std::fprintf(stderr,
               "eval stats: %lu programs run, %lu cancelled at the deadline (%d ms), %.1f s "
               "in all\n",
               g_runs, g_cancelled.load(), g_deadline_ms, g_run_seconds);
}

void start_run() {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_run_start = std::chrono::steady_clock::now();
  g_deadline = g_run_start + std::chrono::milliseconds(g_deadline_ms);
  ++g_generation;
  g_wake.notify_all();
}

void end_run() {
  std::lock_guard<std::mutex> lock(g_mutex);
  ++g_generation;
  ++g_runs;
  g_run_seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - g_run_start).count();
  fuzz::reset_stack_limit();
  g_wake.notify_all();
}

} // namespace

void fuzz_setup() {
  setenv("SICM_INTERPRET", "1", 1);
  if (const char *ms = std::getenv("FUZZ_EVAL_MS")) g_deadline_ms = std::atoi(ms);
  init_interpreter();
  for (const char *name : kExcluded)
    define_primitive(name, 0, kVariadic, Stage::Pure, excluded_primitive); // it only refuses
  set_output_hook(discard_output);
  // Plots are excluded; should one slip through, it lands in a scratch
  // directory, not in the working directory.
  char dir[] = "/tmp/sicm-fuzz-eval-XXXXXX";
  if (mkdtemp(dir)) set_plot_directory(dir);
  snapshot_globals();
  std::atexit(print_stats);
  std::thread(watchdog).detach();
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size > kMaxInput) return -1;
  uint32_t file =
      register_source("<fuzz eval>", std::string(reinterpret_cast<const char *>(data), size));
  std::vector<Symbol *> mentioned;
  try {
    for (const ReadForm &f : read_all(file))
      collect_symbols(f.datum, mentioned);
  } catch (const Error &) {
    return 0; // not a program: the reader target covers this
  }
  start_run();
  try {
    run_source(file);
  } catch (const Error &) {
  } catch (const std::bad_alloc &) {
  }
  end_run();
  flush_output();
  restore_globals(mentioned);
  return 0;
}
