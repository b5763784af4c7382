// What the files of `sicm build`'s partial evaluator share and nothing else
// uses: the state of the build, the run-time values, and the functions each
// part calls in another. pe/build_mode.cpp describes the design and lists
// the files; each declaration below says which file defines it when it is
// not pe/build_mode.cpp.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "base/primitive.hpp"
#include "base/srcloc.hpp"
#include "base/value.hpp"
#include "cas/expr.hpp"
#include "codegen/residual.hpp"
#include "eval/procedure.hpp"

namespace sicm::build {

// ---- limits -------------------------------------------------------------------------------

// Nested tests on run-time values deeper than this are taken for a loop
// whose exit depends on a run-time value.
constexpr int kMaxBranchDepth = 48;
// Alternatives evaluated under such tests in one top-level form, at most.
constexpr long kMaxBranchEvaluations = 200000;

// ---- the state of the build -----------------------------------------------------------------

// Globals assigned while an alternative is evaluated: their values before
// and after, so the other alternative starts from the same state and both
// outcomes can be merged (pe/branches.cpp).
struct Assignment {
  Value *place; // a global's value or a frame slot
  Value before, after;
  uint32_t serial = 0; // the frame's serial (0 for a global)
};

// A variable that holds a run-time list: a list cell (pe/lists.cpp).
struct ListCell {
  Value *place; // the variable (a global's value or a frame slot)
  std::string name;
  int list = -1;            // the list the variable holds now
  bool needs_init = true;   // the next push starts a new list from the variable's value
  std::vector<RType> types; // of the element whose push asked for a new list
};

struct ActiveLoop;  // a loop whose body is being evaluated (pe/loops.cpp)
struct StaticWatch; // a call with known arguments being counted (pe/loops.cpp)

// Everything one build keeps while the program runs in build mode, owned by
// one object: begin_build_mode makes it the build in progress (g_build),
// end_build_mode forgets it. It holds Values, so it lives where the
// collector looks (its owner's stack).
struct BuildState {
  ResidualProgram program; // what the build leaves for run time

  // ---- pe/build_mode.cpp
  std::vector<int> open;                         // functions being traced, innermost last
  std::unordered_map<Symbol *, int> var_ids;     // residual variable of a symbol
  // Per expression node (indexed by ExprId; 0 not yet known): does it
  // mention a variable (1 no, 2 yes), and its RType plus 1 (expr_type).
  std::vector<uint8_t> dynamic_memo, type_memo;
  // Tests on run-time values whose alternatives are being evaluated, nested,
  // in the innermost traced function.
  int branch_depth = 0;
  // Where statements go, innermost last; null: the open function's body (see
  // current_block).
  std::vector<std::vector<RStmt> *> blocks{nullptr};
  uint64_t work = 0; // statements recorded other than output text (see StaticWatch)
  // Per cell of the program: whether main has given it its global's value
  // yet (with_retrace); read_cells reads only those.
  std::vector<bool> cell_initialized;
  gcvec<Frame *> cell_frames; // keeps the frames of local cells alive (a scanned vector)
  std::vector<uint32_t> function_serials; // g_frame_serial when each open function began
  // The primitives rebound, and what each name held before (for end_build_mode).
  std::unordered_map<std::string, PrimFn> original_fns;
  std::vector<Symbol *> rebound;
  gcvec<Value> rebound_values; // scanned: the primitives' objects stay alive
  std::vector<bool> rebound_bound;

  // ---- pe/numerics.cpp: each kernel parameter variable's value, as an
  // expression with the numbers as the decimals they were written as: what
  // the singular factors of a system derivative are computed from, so that
  // they factor and read as the numbers (as sicm run's compile_kernel does)
  std::unordered_map<ExprId, ExprId> parameter_values;
  // what the procedures state-advancer and evolve return print as
  Lambda advancer_lambda, evolver_lambda, crossings_lambda;

  // ---- pe/branches.cpp
  std::vector<gcvec<Assignment> *> undo; // logs of assignments to undo, innermost last
  std::vector<uint32_t> undo_serials;    // g_frame_serial when each log began
  long branch_evaluations = 0;           // alternatives evaluated under tests on run-time values
  std::vector<size_t> capture_depths;    // open.size() when each with-output-to-string began
  // Traces of procedures whose values end as doubles (a system derivative
  // and its Jacobian), nested: there an exact 0 chosen against an inexact
  // number is 0. (select_values).
  int doubles_only = 0;

  // ---- pe/lists.cpp
  std::vector<ListCell> list_cells; // the variables that hold run-time lists
  gcvec<Value> list_cell_elements;  // per cell: the shape of the element that asked for a new list
  gcvec<Value> list_shapes;         // per list: its elements' shape
  std::vector<std::vector<RType>> list_types; // per list: its elements' leaves' kinds

  // ---- pe/loops.cpp
  // The value of a recursive call of the loop being evaluated: it never
  // reaches a result (a test whose alternative it is selects the other).
  Value bottom;
  std::vector<ActiveLoop *> loops; // loops whose bodies are being evaluated, innermost last
  std::vector<StaticWatch *> watches;
  std::unordered_set<Lambda *> unrolled_lambdas; // whose loops could not be left for run time

  // ---- pe/for_run.cpp
  uint32_t trace_serial = 0; // g_frame_serial when a trace for sicm run began
};

// The build in progress, or null (sicm run). The one global of the partial
// evaluator: the evaluator's hooks and the rebound primitives, which are
// plain functions, reach the build through it.
extern BuildState *g_build;

// ---- run-time values ----------------------------------------------------------------------

// A list built at run time (see "lists whose length is known only at run
// time" in pe/lists.cpp): elements [start, end) of the runtime's list
// `list`, read forward from start (reversed: the order they were added) or
// backward from end - 1 (the order of a list built by consing onto its
// front). start and end are counts: exact integers or run-time values.
struct RtList {
  int list;
  bool reversed;
  bool whole; // the whole list as its variable holds it (read again after each call)
  Value start, end;
};

// Throw the compile error "cannot compile: what" at loc.
[[noreturn]] void cannot_compile(SrcLoc loc, const std::string &what);
// Where the evaluator is: the current call, else the current top-level form.
SrcLoc here();
// The innermost function being traced.
RFunction &current();
// Where statements go now: the innermost alternative's block or open function's body.
std::vector<RStmt> &current_block();

// A fresh run-time value (a marker symbol) for a new variable of the current
// function; named `name` instead of a marker for a kernel's inputs, which
// are named as sicm run names them (pe/numerics.cpp).
Value new_var(RType type, const std::string &name = "");
// The residual variable v stands for, or -1.
int var_of(Value v);
// v as a run-time list, or null.
RtList *as_rtlist(Value v);
// A new run-time list (see RtList).
Value make_rtlist(int list, bool reversed, bool whole, Value start, Value end);
// A run-time number: a variable, or an expression that mentions one.
bool is_dynamic_scalar(Value v);
// A run-time truth value.
bool is_dynamic_boolean(Value v);
// Does v hold a run-time value or list anywhere (in pairs, structures, vectors)?
bool contains_dynamic(Value v);
// v written for an error message, run-time values as <run-time number>.
std::string describe(Value v);
// s with the build's name of each run-time number written <run-time number>.
std::string without_markers(std::string s);
// A number, a boolean or a run-time value as an expression node (who: for the error).
ExprId expr_of(Value v, const char *who);
// The kind of number (or truth value) v would print as.
RType scalar_type(Value v);
// A number, a truth value or a run-time number.
bool is_scalar(Value v);

// ---- statements and cells -----------------------------------------------------------------

struct Retrace {}; // thrown to trace the current numerical primitive again

// Record a statement in the current block (reading the cells again after a call).
void emit(RStmt s);
// The index of the cell whose global's value (or frame slot) is *place, or -1.
int cell_of(Value *place);
// Record the assignment of v to a cell.
void set_cell(int cell, Value v);
// Make every cell's global hold a fresh read of the cell in the current function.
void read_cells();
// Run a numerical primitive, tracing it again on Retrace.
Value with_retrace(const std::function<Value()> &body);
// How far the build had got when an attempt at residual code began (a
// trace that may be retraced or fail, a loop tried as a C loop, a call
// evaluated tentatively), and restore() to forget everything the attempt
// made: the program's functions, variables (and their symbols' entries in
// var_ids and parameter_values), lists and tables, the statements added to
// the current function's body and to the current block, and the values of
// the list cells' variables. Defined in pe/checkpoint.cpp, which says what
// it leaves alone and why (cells, effort counters, the evaluator's
// variables: each attempt's scope undoes its own assignment log).
class Checkpoint {
public:
  Checkpoint();
  Checkpoint(const Checkpoint &) = delete;
  Checkpoint &operator=(const Checkpoint &) = delete;
  void restore() const;
  size_t nfunctions() const { return nfunctions_; }

private:
  size_t nfunctions_, nvars_, nlists_, ntables_;
  int function_;              // the current function, or -1
  size_t nbody_;              // its statements then
  std::vector<RStmt> *block_; // the current block when it is not the body, or null
  size_t nblock_;             // its statements then
  gcvec<Value> list_places_;  // the list cells' variables then
};
// Is e cannot_compile's error?
bool is_cannot_compile(const Error &e);
// A new variable of the given type computed by c from args.
Value let(RCompute c, std::vector<ExprId> args, RType type);

// ---- rebound primitives -------------------------------------------------------------------

// Call the primitive `name` as it was before begin_build_mode rebound it.
Value call_original(const char *name, Value *a, int n);
// Define the primitive `name` as fn, keeping the one it replaces for call_original.
void rebind(const char *name, int min, int max, PrimFn fn);

// ---- branches on run-time values (pe/branches.cpp) -------------------------------------

// Add a to the innermost log, if its variable is older than the log.
void log_assignment(const Assignment &a);
// Does the block call a function or add to a list (after which cells and
// lists are read again)?
bool block_calls(const std::vector<RStmt> &block);
// The value that is `a` when the run-time truth value `test` holds and `b`
// otherwise (numbers, structures, pairs, run-time lists, differentials).
Value select_values(Value test, Value a, Value b);

// The evaluator's hooks (DynamicBranchHooks in eval/procedure.hpp).
bool hook_dynamic_test(Value test);
Value hook_branch(Value test, Node *then, Node *else_, Frame *env);
Value hook_logic(Value test, Node *n, uint32_t from, bool is_and, Frame *env);
Value hook_set_global(Symbol *s, Value v, SrcLoc loc);
Value hook_set_local(Frame *f, uint32_t index, Value v, SrcLoc loc);
void hook_forcing(Value promise);
void hook_capture();

// ---- procedures traced into functions (pe/numerics.cpp) ----------------------------

// Run `body` with a new function of the residual program open (named `name`,
// a child of the open one): the statements it causes go to the new
// function's body, and the cells and list variables are as the caller sees
// them again afterwards. Returns the function's id.
int in_new_function(const std::string &name, const std::function<void()> &body);
// Trace a scalar function (integrand, objective, function with a root) into
// a new function of one input and one output; returns its id.
int trace_scalar(Value f, const char *who);
// Trace a system derivative into a new function from the leaves of a state
// shaped like `state` to the leaves of its derivative; returns its id.
int trace_system_function(Value sysder, Value state, const char *who);
// Trace an event (a real function of a state shaped like `state`) into a
// new function from the state's leaves to its one value; returns its id.
int trace_event_function(Value event, Value state, const char *who);
// A value shaped like `sample` (a number, or an up/down structure of them)
// whose leaves are fresh inputs of the open function.
Value input_like(Value sample);
// Is v a number, a run-time scalar, or an up/down structure of them?
bool is_state_shape(Value v);
// The name of a closure's lambda, or "anonymous".
std::string procedure_name(Value proc);

// ---- loops (pe/loops.cpp) --------------------------------------------------------------

struct LoopRetry {}; // evaluate the loop's body again with more loop variables

extern const OpaqueKind kBottomKind; // the kind of BuildState::bottom

// Throw LoopAbort: what is being evaluated as a loop is not one.
[[noreturn]] void throw_not_a_loop();
// Is v the value of a recursive call of a loop (g_build->bottom)?
bool is_bottom(Value v);
// The scalar leaves of a loop's result (a number or truth value, or a proper
// list, structure or vector of them); false if it has others.
bool result_leaves(Value v, gcvec<Value> &out);
// A value shaped like `shape` (as result_leaves walks it) with new leaves.
Value result_like(Value shape, const Value *&leaves);
// Do a and b have the same shape as loop values?
bool same_shape(Value a, Value b);
// Is a variable of `frame` (null: a global) kept from one iteration to the
// next of the loop being evaluated for run time, in the same function?
bool grows_in_loop(Frame *frame);
// (map f l ...) or (for-each f l ...) over lists known at compile time as a
// C loop, past --max-unrolled-elements; false to unroll it.
bool map_over_static_lists(Value *a, int n, bool collect, const char *who, Value *out);
// Does applying f to args record run-time work (statements other than
// output text, or a run-time result)? Evaluated and forgotten.
bool does_run_time_work(Value f, gcvec<Value> args);
// Evaluate `body` tentatively: what it made is kept if it returns true, and
// forgotten (variables, functions, lists, tables, statements, assignments)
// if it returns false or raises an Error, which is then swallowed.
bool tentatively(const std::function<bool()> &body);
// The evaluator's hook for calls of closures.
bool hook_call_closure(Value f, Value *slots, long n, Value *out);

// ---- lists whose length is known only at run time (pe/lists.cpp) -----------------------

// The index of the list cell whose variable is *place, or -1.
int list_cell_of(const Value *place);
// The variables of the list cells, in order.
std::vector<Value *> list_cell_places();
// Is v a run-time list as its list cell's variable holds it (all of it)?
bool is_whole_list(Value v);
// The leaves of a list element, or false if it cannot be one.
bool element_leaves(Value v, gcvec<Value> &out);
// The shape of an element: its leaves replaced by 0.
Value element_shape(Value element);
// A new empty run-time list for elements shaped like `shape` with leaves of
// `types` (a ListNew statement); its id.
int new_list(Value shape, const std::vector<RType> &types, const std::string &name);
// (set! l (cons element l)) where l must become or is a run-time list.
Value push_onto_list(Value *place, const std::string &name, Value element, SrcLoc loc,
                     bool may_create, Frame *frame, bool in_loop);
// Start the lists that pushes asked for, from the values their variables hold.
void init_list_cells();
// A list cell's variable holding its whole list gets the list's length now.
void read_list_cells();
// (map f l ...) or (for-each f l ...) over run-time lists, as a C loop.
Value map_over_lists(Value f, Value *lists, int nlists, bool collect, const char *who);
// The evaluator's hook for apply with a run-time list as its last argument.
bool hook_apply_to_other(Value f, Value *args, long nargs, Value *out);

} // namespace sicm::build
