// Named limits on evaluation (steps, memory, expression nodes, recursion
// depth, residual size) and interrupting it with Ctrl-C (see limits.cpp).
//
// Every limit is a command-line flag with a documented default. Hitting one
// is an Error naming the limit and its flag, at the place evaluation had
// reached, so `sicm run` exits 70, `sicm build` 65 and the REPL carries on.
//
// The unroll limits of sicm build are different: hitting one is never an
// error. Past them the partial evaluator generalizes (leaves a loop for run
// time) instead of unrolling it (see pe/loops.cpp).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "base/srcloc.hpp"

namespace sicm {

constexpr uint64_t kUnlimited = UINT64_MAX;

// A value of 0 stands for "the default" until with_defaults fills it in.
struct Limits {
  uint64_t max_steps = 0;               // iterations of the evaluator's loop
  uint64_t max_memory = 0;              // bytes of collected heap
  uint64_t max_expression_nodes = 0;    // new nodes in the expression arena
  uint64_t max_recursion_depth = 0;     // levels of non-tail recursion
  uint64_t max_residual_size = 0;       // statements of a built program
  uint64_t max_unrolled_elements = 0;   // sicm build: see kMaxUnrolledElements
  uint64_t max_unrolled_iterations = 0; // sicm build: see kMaxUnrolledIterations
  uint64_t max_compiled_kernels = 0;    // see kMaxCompiledKernels
};

// Distinct compiled procedures (shared objects: kernels that differ in
// structure, not only in the values of their numbers) one process loads;
// past this many, procedures not compiled already are interpreted, and a
// note on stderr says so once, at the user's line (--max-compiled-kernels).
// Loaded code is never unloaded, so the limit bounds its memory.
constexpr uint64_t kMaxCompiledKernels = 2000;

// sicm build unrolls map and for-each over a list known at compile time
// whose body does run-time work (calls a numerical primitive, plots) only
// for lists of at most this many elements; a longer list of inexact numbers
// (or of pairs or structures of them, all of one shape) becomes a constant
// table in the executable and the body a C loop over it
// (--max-unrolled-elements).
constexpr uint64_t kMaxUnrolledElements = 32;
// sicm build evaluates a named procedure called with arguments known at
// compile time as sicm run does, unrolling its recursion, until it has
// called itself this many times while its calls record run-time work; then
// it evaluates the first call again as a C loop whose variables are the
// arguments that change from call to call (--max-unrolled-iterations).
// Loops that do no run-time work run at compile time however long they are.
constexpr uint64_t kMaxUnrolledIterations = 64;

// The limits given, with the defaults of a command in place of the rest.
// compile_time: build and emit-c, whose steps are limited by default too.
Limits with_defaults(Limits given, bool compile_time);

// Remove the limit flags (--max-steps=N or --max-steps N, and so on) from
// args, storing their values in *given. False, with a message in *error, for
// a malformed value or an unknown --max- flag.
bool take_limit_flags(std::vector<std::string> &args, Limits *given, std::string *error);

// The usage text's lines about the limit flags.
std::string limits_usage();

// The recursion depth limit is a limit on the evaluator's stack: N levels
// may use N times the stack of one level of plain non-tail recursion. The
// stack guard's allowance for a limit, and the evaluator thread's stack
// reservation (the allowance and a margin for the primitives).
size_t recursion_stack_bytes(const Limits &limits);
size_t evaluator_stack_bytes(const Limits &limits);

// Put limits (with defaults filled in) in force and start counting a new
// evaluation from zero. Call on the evaluator thread after init_interpreter,
// so the library's loading does not count. compile_time: errors are compile
// errors (exit 65), else run-time errors (exit 70).
void set_limits(const Limits &limits, bool compile_time);

// A new top-level entry of the REPL, evaluating the form at `where`: steps
// and expression nodes count from zero again, a pending interrupt is
// forgotten.
void begin_evaluation(SrcLoc where);

// Ctrl-C: async-signal-safe; evaluation raises "Interrupted" at its next
// check (within a few thousand steps or one new expression node) and at
// every check after it until begin_evaluation.
void request_interrupt();

// The interrupt request as a plain int, for compiled loops to poll (see
// codegen/residual_emit.hpp emit_residual_function).
const volatile int *interrupt_flag();

// sicm build: one more statement in the residual program, emitted at
// `where`; raises the residual size error past the limit.
void note_residual_statement(SrcLoc where);

// The limits in force (with defaults filled in), as set_limits set them.
const Limits &current_limits();

// How many nodes the expression arena holds (cas/expr.cpp's expr_count,
// given at start-up by driver/init.cpp; until then none are counted).
using NodeCounter = size_t (*)();
void set_expression_node_counter(NodeCounter count);

// Steps taken since the evaluation began (for tests and measurements).
uint64_t steps_taken();

// The location errors raised outside the evaluator loop report (eval.cpp).
void reset_call_loc(SrcLoc where);

// The stack guard tripped (check_stack): the recursion depth error.
[[noreturn]] void stack_exhausted(SrcLoc where);

// While one lives, at most `nodes` more expression nodes may be made (and
// never more than the limit in force allows); past that, the expression
// size limit's error is raised as usual. For work that has a cheaper way
// out when it grows (kernel_outputs tries the canonical form of a kernel
// within one and keeps the traced form if it does not fit). Nests.
class ExpressionBudget {
public:
  explicit ExpressionBudget(uint64_t nodes);
  ~ExpressionBudget();
  ExpressionBudget(const ExpressionBudget &) = delete;
  ExpressionBudget &operator=(const ExpressionBudget &) = delete;

private:
  uint64_t saved_ceiling_;
};

// ---- the evaluator's hot path ------------------------------------------------
// Inline: eval() pays one decrement per step.
namespace limits_detail {
extern int64_t fuel;          // steps left before the next checkpoint
extern uint64_t expr_ceiling; // the arena size at which new nodes fail
extern std::atomic<int> interrupt;
void checkpoint(SrcLoc where);
void expression_check(size_t count);
} // namespace limits_detail

// One evaluation step at `where`: a decrement, and a real check every few
// thousand steps.
inline void count_step(const SrcLoc &where) {
  if (--limits_detail::fuel < 0) [[unlikely]]
    limits_detail::checkpoint(where);
}

// The simplifier is about to expand a product or power in FLINT, outside
// the arena, into a polynomial of up to `terms` terms (an upper bound), each
// of which becomes a node or more when it is turned back into an
// expression: the expression size error now, naming `what`, if they would
// not fit in what is left of the limit, rather than after minutes in FLINT
// (which the interrupt cannot stop either).
void check_expression_growth(double terms, const char *what);

// The expression arena, holding `count` nodes, is about to make another.
inline void check_expression_nodes(size_t count) {
  if (count >= limits_detail::expr_ceiling ||
      limits_detail::interrupt.load(std::memory_order_relaxed)) [[unlikely]]
    limits_detail::expression_check(count);
}

} // namespace sicm
