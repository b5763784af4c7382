// Named limits on evaluation, their flags and defaults, and Ctrl-C.
//
// A program that loops forever, allocates without end, builds an expression
// that never stops growing or recurses without bound must end with an error
// that says which limit it hit and where it was, never with the machine
// swapping or the kernel's out-of-memory killer. Each limit is checked where
// the resource is spent, as cheaply as that allows:
//
//   steps       the evaluator's loop decrements a counter (`fuel`) per
//               iteration; every kCheckInterval steps the counter runs out
//               and checkpoint() compares the total with the limit and looks
//               at the interrupt flag. Ctrl-C is seen within that many steps.
//   memory      the collector itself: GC_set_max_heap_size stops the heap
//               from growing past the limit, and when an allocation cannot
//               be met the collector calls on_out_of_memory (outside its
//               lock), which throws the limit error from the allocation.
//               Memory outside the collected heap (the expression arena,
//               GMP's numbers, the stack) is not counted: the expression
//               and recursion limits bound the first and the last.
//   expression  the arena checks its size before adding a node (expr.cpp).
//   recursion   the stack guard that eval() already passes on every entry
//               (check_stack, a comparison of the stack pointer) allows N
//               times the stack one level of plain non-tail recursion takes,
//               and the evaluator's thread gets a stack that big. A count
//               of nested evaluations would be exact, but keeping it right
//               needs a destructor in eval(), which stops eval's calls in
//               tail position from being compiled as jumps and so makes
//               each level take half as much stack again; and every
//               evaluation that recurses through a primitive (map, sort)
//               really does use more of the resource being limited.
//   residual    sicm build counts the statements it records.
//   unrolling   not errors: sicm build reads --max-unrolled-elements and
//               --max-unrolled-iterations (current_limits) to decide when to
//               leave a loop for run time instead of unrolling it.
//
// Once a limit is hit every later check of it fails too (the step count
// stays past the limit, the interrupt flag stays set), so an error caught on
// the way out, by code that falls back to another strategy when something
// fails, cannot make the evaluation carry on. The REPL starts each entry
// afresh with begin_evaluation.
#include "base/limits.hpp"

#include <gc/gc.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <fstream>

#include "base/error.hpp"

namespace sicm {

namespace {

// ---- the defaults ----------------------------------------------------------------
// Measured on every test and example (docs/reliability.md has the table):
// the most any of them takes is 1.6e8 steps (a stress test of tail calls;
// 4e7 for the heaviest scene), 80 MB of heap, 2.8 million expression nodes
// and 207 000 residual statements (the full-size driven pendulum section
// under sicm build), and 1 000 nodes under sicm run.
//
// Steps are unlimited for `sicm run` and the REPL, where a long interpreted
// simulation is legitimate and Ctrl-C is at hand; `sicm build` evaluates at
// compile time, where a program that does not stop is a compiler that
// hangs. 1e9 steps of a simple loop take about 30 seconds.
constexpr uint64_t kDefaultBuildSteps = 1'000'000'000;
// The collected heap: 8 GiB, or half the physical memory (or of the
// cgroup's memory.max) when that is less.
constexpr uint64_t kDefaultMemory = uint64_t(8) << 30;
// New expression nodes: each takes about 48 bytes with its arguments and
// its share of the hash table, so 30 million are about 1.5 GB (outside the
// collected heap), and take some 20 seconds to build.
constexpr uint64_t kDefaultExpressionNodes = 30'000'000;
// Levels of plain non-tail recursion: a million, about what the historical
// 256 MiB stack held.
constexpr uint64_t kDefaultRecursionDepth = 1'000'000;
// Statements of a residual program: ten times the largest scene's.
constexpr uint64_t kDefaultResidualSize = 2'000'000;

// The stack allowed per level of the recursion limit: a level of
// (define (count n) (if (= n 0) 0 (+ 1 (count (- n 1))))) takes about 230
// bytes on x86-64 with gcc 12 -O2 (the frames of eval, call_evaluated and
// evaluate_operands), so N levels of it always fit; recursion through a
// primitive (map, sort) takes two to four times as much per level. Then
// what is kept free beyond that for the primitives and the collector, and
// the least stack reserved (what sicm always had).
constexpr size_t kStackBytesPerLevel = 256;
constexpr size_t kStackMargin = size_t(16) << 20;
constexpr size_t kMinStackBytes = size_t(256) << 20;

// Steps between checkpoints: small enough that Ctrl-C answers within a
// millisecond, large enough that the checkpoint costs nothing measurable.
constexpr int64_t kCheckInterval = 4096;

Limits g_limits = {kUnlimited,
                   0,
                   kUnlimited,
                   kUnlimited,
                   kUnlimited,
                   kMaxUnrolledElements,
                   kMaxUnrolledIterations,
                   kMaxCompiledKernels};
NodeCounter g_node_counter = nullptr;

size_t node_count() {
  return g_node_counter ? g_node_counter() : 0;
}

bool g_compile_time = false;
bool g_active = false; // set_limits has run
uint64_t g_steps_base = 0;
int64_t g_grant = 0;
uint64_t g_expr_base = 0;
uint64_t g_residual = 0;

// ---- the errors -------------------------------------------------------------------

[[noreturn]] void limit_error(SrcLoc where, const std::string &msg,
                              ErrorCause cause = ErrorCause::Limit) {
  throw Error(g_compile_time ? ErrorKind::Syntax : ErrorKind::Runtime, cause, where, msg);
}

// Where evaluation is, for errors raised outside the evaluator's loop.
SrcLoc somewhere() {
  SrcLoc loc = current_call_loc();
  return loc.known() ? loc : current_toplevel_loc();
}

std::string show_count(uint64_t n) {
  return n == kUnlimited ? "unlimited" : std::to_string(n);
}

// A count estimated in floating point: exact digits while they are
// meaningful, then scientific notation.
std::string show_estimate(double n) {
  char buf[32];
  std::snprintf(buf, sizeof buf, n < 1e15 ? "%.0f" : "%.3g", n);
  return buf;
}

std::string show_bytes(uint64_t n) {
  if (n == kUnlimited) return "unlimited";
  const char *units = "KMGT";
  int u = -1;
  while (u < 3 && n % 1024 == 0 && n >= 1024) {
    n /= 1024;
    ++u;
  }
  return std::to_string(n) + (u >= 0 ? std::string(1, units[u]) : "");
}

[[noreturn]] void interrupted(SrcLoc where) {
  limit_error(where, "Interrupted", ErrorCause::Interrupted);
}

// ---- memory -----------------------------------------------------------------------

uint64_t physical_memory() {
  long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGESIZE);
  uint64_t total = pages > 0 && size > 0 ? uint64_t(pages) * uint64_t(size) : kUnlimited;
  std::ifstream cgroup("/sys/fs/cgroup/memory.max");
  uint64_t cap;
  if (cgroup >> cap) total = std::min(total, cap); // "max" reads as no number
  return total;
}

GC_warn_proc g_gc_warn = nullptr;

// The collector's warnings, less the one it prints when the heap is full:
// the limit error says it better.
void GC_CALLBACK filter_gc_warning(char *msg, GC_word arg) {
  if (std::string(msg).find("Out of Memory") != std::string::npos) return;
  if (g_gc_warn) g_gc_warn(msg, arg);
}

// Called by the collector, without its lock held, when it cannot find
// `bytes` even after collecting. Throwing unwinds through the collector's C
// frames (built with unwind tables) back to the allocation.
void *GC_CALLBACK on_out_of_memory(size_t bytes) {
  uint64_t heap = GC_get_heap_size();
  uint64_t max = g_limits.max_memory;
  bool at_limit = max != kUnlimited && (bytes >= max || heap + bytes + (uint64_t(1) << 20) >= max);
  if (at_limit)
    limit_error(somewhere(), "memory limit (--max-memory=" + show_bytes(max) + ") exceeded");
  limit_error(somewhere(), "out of memory: the system refused to grow the heap past " +
                               std::to_string(heap >> 20) + " MiB");
}

// ---- parsing ----------------------------------------------------------------------

struct Flag {
  const char *name;
  uint64_t Limits::*field;
  bool bytes; // takes K, M, G and T suffixes
  bool allow_unlimited;
};

const Flag kFlags[] = {
    {"--max-steps", &Limits::max_steps, false, true},
    {"--max-memory", &Limits::max_memory, true, true},
    {"--max-expression-nodes", &Limits::max_expression_nodes, false, true},
    {"--max-recursion-depth", &Limits::max_recursion_depth, false, false},
    {"--max-residual-size", &Limits::max_residual_size, false, true},
    {"--max-unrolled-elements", &Limits::max_unrolled_elements, false, true},
    {"--max-unrolled-iterations", &Limits::max_unrolled_iterations, false, true},
    {"--max-compiled-kernels", &Limits::max_compiled_kernels, false, true},
};

// The largest recursion depth accepted (the stack grows with it).
constexpr uint64_t kMaxRecursionDepth = 100'000'000;

bool mul_overflows(uint64_t a, uint64_t b, uint64_t *out) {
  return __builtin_mul_overflow(a, b, out);
}

// A count: digits, or digits 'e' digits (1e9); a size: digits and an
// optional K, M, G or T (powers of 1024).
bool parse_value(const Flag &f, const std::string &text, uint64_t *out) {
  if (text == "unlimited") {
    *out = kUnlimited;
    return f.allow_unlimited;
  }
  size_t i = 0;
  uint64_t v = 0;
  while (i < text.size() && text[i] >= '0' && text[i] <= '9') {
    if (mul_overflows(v, 10, &v) || __builtin_add_overflow(v, uint64_t(text[i] - '0'), &v))
      return false;
    ++i;
  }
  if (i == 0) return false;
  if (i < text.size()) {
    std::string rest = text.substr(i);
    uint64_t scale = 1;
    if (f.bytes && rest.size() == 1) {
      size_t at = std::string("KMGT").find(static_cast<char>(std::toupper(rest[0])));
      if (at == std::string::npos) return false;
      scale = uint64_t(1) << (10 * (at + 1));
    } else if (!f.bytes && rest[0] == 'e' && rest.size() > 1 && rest.size() <= 3 &&
               rest.find_first_not_of("0123456789", 1) == std::string::npos) {
      for (int e = std::stoi(rest.substr(1)); e > 0; --e)
        if (mul_overflows(scale, 10, &scale)) return false;
    } else {
      return false;
    }
    if (mul_overflows(v, scale, &v)) return false;
  }
  if (v == 0 || v == kUnlimited) return false;
  if (f.field == &Limits::max_recursion_depth && v > kMaxRecursionDepth) return false;
  *out = v;
  return true;
}

std::string value_help(const Flag &f) {
  std::string s = f.bytes ? "a number of bytes, optionally ending in K, M, G or T"
                          : "a positive whole number (like 1000000 or 1e6)";
  if (f.field == &Limits::max_recursion_depth) s += " of at most 1e8";
  if (f.allow_unlimited) s += ", or unlimited";
  return s;
}

} // namespace

// ---- the hot path's state ----------------------------------------------------------

namespace limits_detail {
int64_t fuel = 0;
uint64_t expr_ceiling = kUnlimited;
std::atomic<int> interrupt{0};

// The fuel ran out: the step being taken is number g_steps_base + g_grant + 1.
void checkpoint(SrcLoc where) {
  g_steps_base += static_cast<uint64_t>(g_grant);
  g_grant = 0;
  fuel = 0; // consistent if we throw: the next step comes back here
  if (interrupt.load(std::memory_order_relaxed)) interrupted(where);
  uint64_t max = g_limits.max_steps;
  if (g_steps_base >= max)
    limit_error(where, "evaluation step limit (--max-steps=" + show_count(max) + ") exceeded");
  g_grant = static_cast<int64_t>(std::min<uint64_t>(kCheckInterval, max - g_steps_base));
  fuel = g_grant - 1; // this step
}

void expression_check(size_t count) {
  if (interrupt.load(std::memory_order_relaxed)) interrupted(somewhere());
  if (count >= expr_ceiling)
    limit_error(somewhere(), "expression size limit (--max-expression-nodes=" +
                                 show_count(g_limits.max_expression_nodes) + ") exceeded");
}
} // namespace limits_detail

// ---- the interface -------------------------------------------------------------------

Limits with_defaults(Limits given, bool compile_time) {
  Limits l = given;
  if (!l.max_steps) l.max_steps = compile_time ? kDefaultBuildSteps : kUnlimited;
  if (!l.max_memory) l.max_memory = std::min(kDefaultMemory, physical_memory() / 2);
  if (!l.max_expression_nodes) l.max_expression_nodes = kDefaultExpressionNodes;
  if (!l.max_recursion_depth) l.max_recursion_depth = kDefaultRecursionDepth;
  if (!l.max_residual_size) l.max_residual_size = kDefaultResidualSize;
  if (!l.max_unrolled_elements) l.max_unrolled_elements = kMaxUnrolledElements;
  if (!l.max_unrolled_iterations) l.max_unrolled_iterations = kMaxUnrolledIterations;
  if (!l.max_compiled_kernels) l.max_compiled_kernels = kMaxCompiledKernels;
  return l;
}

bool take_limit_flags(std::vector<std::string> &args, Limits *given, std::string *error) {
  std::vector<std::string> rest;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string &a = args[i];
    if (a.rfind("--max-", 0) != 0) {
      rest.push_back(a);
      continue;
    }
    size_t eq = a.find('=');
    std::string name = a.substr(0, eq);
    const Flag *flag = nullptr;
    for (const Flag &f : kFlags)
      if (name == f.name) flag = &f;
    if (!flag) {
      *error = "unknown option " + name;
      return false;
    }
    std::string value;
    if (eq != std::string::npos) {
      value = a.substr(eq + 1);
    } else if (i + 1 < args.size()) {
      value = args[++i];
    } else {
      *error = name + " needs a value: " + value_help(*flag);
      return false;
    }
    if (!parse_value(*flag, value, &(given->*flag->field))) {
      *error = name + "=" + value + ": the value must be " + value_help(*flag);
      return false;
    }
  }
  args.swap(rest);
  return true;
}

std::string limits_usage() {
  Limits here = with_defaults({}, false);
  return "limits, for run, build, emit-c, emit-kernels and repl (N may be written 1e6;\n"
         "a SIZE may end in K, M, G or T; `unlimited` lifts a limit; the repl counts\n"
         "steps and expression nodes afresh for each entry):\n"
         "  --max-steps=N             evaluation steps; default unlimited, but " +
         show_count(kDefaultBuildSteps) +
         "\n"
         "                            for build and emit-c\n"
         "  --max-memory=SIZE         collected heap; default " +
         show_bytes(kDefaultMemory) +
         ", or half the memory\n"
         "                            if less (here " +
         show_bytes(here.max_memory) +
         ")\n"
         "  --max-expression-nodes=N  new symbolic expression nodes; default " +
         show_count(kDefaultExpressionNodes) +
         "\n"
         "  --max-recursion-depth=N   levels of non-tail recursion; default " +
         show_count(kDefaultRecursionDepth) +
         "\n"
         "  --max-residual-size=N     statements of a built program; default " +
         show_count(kDefaultResidualSize) +
         "\n"
         "  --max-unrolled-elements=N build: map and for-each over a longer list of\n"
         "                            inexact numbers known at compile time become a C\n"
         "                            loop when they do run-time work; default " +
         show_count(kMaxUnrolledElements) +
         "\n"
         "  --max-unrolled-iterations=N\n"
         "                            build: a loop that starts from known values and\n"
         "                            does run-time work is unrolled this far, then left\n"
         "                            for run time as a C loop; default " +
         show_count(kMaxUnrolledIterations) +
         "\n"
         "  --max-compiled-kernels=N  distinct compiled procedures (kernels that differ\n"
         "                            in structure) one process loads; past it they are\n"
         "                            interpreted, with a note; default " +
         show_count(kMaxCompiledKernels) + "\n";
}

size_t recursion_stack_bytes(const Limits &limits) {
  uint64_t depth = limits.max_recursion_depth ? limits.max_recursion_depth : kDefaultRecursionDepth;
  return static_cast<size_t>(depth) * kStackBytesPerLevel;
}

size_t evaluator_stack_bytes(const Limits &limits) {
  return std::max(kMinStackBytes, recursion_stack_bytes(limits) + kStackMargin);
}

void set_limits(const Limits &limits, bool compile_time) {
  // Without the arena's counter the expression limit would count from zero.
  SICM_ASSERT(g_node_counter);
  g_limits = with_defaults(limits, compile_time);
  g_compile_time = compile_time;
  if (!g_active) {
    g_gc_warn = GC_get_warn_proc();
    GC_set_warn_proc(filter_gc_warning);
    GC_set_oom_fn(on_out_of_memory);
    // When the heap may not grow, collect before giving up: by default the
    // collector fails at once unless enough was allocated since its last
    // collection, which after one limit error (the garbage of the failed
    // evaluation filling the heap) is never the case.
    GC_set_max_retries(1);
    g_active = true;
  }
  GC_set_max_heap_size(g_limits.max_memory == kUnlimited ? 0 : g_limits.max_memory);
  g_residual = 0;
  begin_evaluation(SrcLoc{});
}

void begin_evaluation(SrcLoc where) {
  g_steps_base = 0;
  g_grant = 0;
  limits_detail::fuel = 0;
  limits_detail::interrupt.store(0, std::memory_order_relaxed);
  g_expr_base = node_count();
  uint64_t max = g_limits.max_expression_nodes;
  limits_detail::expr_ceiling =
      max == kUnlimited || max > kUnlimited - g_expr_base ? kUnlimited : g_expr_base + max;
  reset_call_loc(where);
}

void set_expression_node_counter(NodeCounter count) {
  g_node_counter = count;
}

ExpressionBudget::ExpressionBudget(uint64_t nodes) : saved_ceiling_(limits_detail::expr_ceiling) {
  uint64_t now = node_count();
  uint64_t ceiling = nodes > kUnlimited - now ? kUnlimited : now + nodes;
  limits_detail::expr_ceiling = std::min(saved_ceiling_, ceiling);
}

ExpressionBudget::~ExpressionBudget() {
  limits_detail::expr_ceiling = saved_ceiling_;
}

void check_expression_growth(double terms, const char *what) {
  if (limits_detail::interrupt.load(std::memory_order_relaxed)) interrupted(somewhere());
  uint64_t ceiling = limits_detail::expr_ceiling;
  if (ceiling == kUnlimited) return;
  double room = static_cast<double>(ceiling) - static_cast<double>(node_count());
  if (terms < room) return;
  limit_error(somewhere(), "expression size limit (--max-expression-nodes=" +
                               show_count(g_limits.max_expression_nodes) + ") exceeded: " + what +
                               " could have up to " + show_estimate(terms) + " terms");
}

static_assert(sizeof(std::atomic<int>) == sizeof(int) && std::atomic<int>::is_always_lock_free,
              "compiled code reads the interrupt request as an int");

const volatile int *interrupt_flag() {
  return reinterpret_cast<const volatile int *>(&limits_detail::interrupt);
}

void request_interrupt() {
  limits_detail::interrupt.store(1, std::memory_order_relaxed);
}

void note_residual_statement(SrcLoc where) {
  if (++g_residual > g_limits.max_residual_size)
    limit_error(where.known() ? where : somewhere(),
                "residual code size limit (--max-residual-size=" +
                    show_count(g_limits.max_residual_size) + ") exceeded");
}

void stack_exhausted(SrcLoc where) {
  limit_error(where, "Aborting!: maximum recursion depth exceeded (--max-recursion-depth=" +
                         show_count(g_limits.max_recursion_depth) + ")");
}

const Limits &current_limits() {
  return g_limits;
}

uint64_t steps_taken() {
  return g_steps_base + static_cast<uint64_t>(g_grant - limits_detail::fuel);
}

} // namespace sicm
