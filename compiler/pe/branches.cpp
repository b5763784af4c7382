// `sicm build`'s branches on run-time values: `if`, `and` and `or` on a
// run-time truth value evaluate both alternatives, each into its own block
// of statements (a C if/else), and select between their values and the
// variables they assign; set! of a variable kept from one run-time call to
// the next makes it a cell or a run-time list. These are the evaluator's
// hooks (DynamicBranchHooks). Part of build mode (the design is in
// pe/build_mode.cpp; the shared declarations in pe/state.hpp).
#include <algorithm>
#include <functional>
#include <string>

#include "algebra/differential.hpp"
#include "algebra/generic.hpp"
#include "algebra/structure.hpp"
#include "base/number.hpp"
#include "eval/core.hpp"
#include "eval/procedure.hpp"
#include "pe/specialized.hpp"
#include "pe/state.hpp"

namespace sicm::build {

// g_frame_serial when each log began: a local variable of a frame made
// later belongs to the alternative (or loop body) itself and is not logged.

// Add a to the innermost log, if its variable is older than the log.
void log_assignment(const Assignment &a) {
  if (!g_build->undo.empty() && a.serial <= g_build->undo_serials.back())
    g_build->undo.back()->push_back(a);
}

// Does the block call a function or add to a list (after which cells and
// lists are read again)?
bool block_calls(const std::vector<RStmt> &block) {
  for (const RStmt &s : block)
    if (s.callee >= 0 || s.monitor >= 0 || s.first_monitor >= 0 || !s.members.empty() ||
        s.kind == RKind::ListPush || block_calls(s.then_body) || block_calls(s.else_body))
      return true;
  return false;
}

namespace {

bool is_inexact_scalar(Value v) {
  return v.is(Tag::Flonum) || (is_dynamic_scalar(v) && scalar_type(v) == RType::Real);
}

// Inside a system derivative (g_build->doubles_only), whose values end as
// doubles, an exact 0 chosen against an inexact number is 0.: a potential
// that is 0 on one side ((if (> x 0) (* 1/2 k x x) 0)), and the derivative
// of such a constant arm, are as inexact as the other arm, since which arm
// holds is known only at run time. Elsewhere (a value printed at the top
// level, a monitor) the kinds must agree as the printed form depends on
// them.
void match_exact_zero(Value &a, Value &b) {
  if (g_build->doubles_only == 0) return;
  if (is_exact_zero(a) && is_inexact_scalar(b)) a = Value::flonum(0.0);
  if (is_exact_zero(b) && is_inexact_scalar(a)) b = Value::flonum(0.0);
}

// Two differentials chosen between term by term; a term one of them lacks
// is an exact 0.
Value select_differentials(Value test, Value a, Value b) {
  return combine_differential_terms(a, b,
                                    [&](Value x, Value y) { return select_values(test, x, y); });
}

} // namespace

// The value that is `a` when test holds at run time and `b` otherwise.
Value select_values(Value test, Value a, Value b) {
  if (eqv(a, b)) return a;
  if (is_bottom(a)) return b; // that alternative goes on with the next iteration
  if (is_bottom(b)) return a;
  bool a_scalar = is_number(a) || a.is(Tag::Bool) || is_dynamic_scalar(a);
  bool b_scalar = is_number(b) || b.is(Tag::Bool) || is_dynamic_scalar(b);
  if (a_scalar && b_scalar) {
    // The printed form depends on the kind of number, which must not
    // depend on the test: both truth values, both exact integers (or
    // counts), or both inexact.
    match_exact_zero(a, b);
    RType ta = scalar_type(a), tb = scalar_type(b);
    if (ta != tb)
      cannot_compile(here(), "the alternatives of a test on a value known only at run time give " +
                                 describe(a) + " and " + describe(b) +
                                 ", numbers of different kinds (exact and inexact)" +
                                 (is_exact_zero(a) || is_exact_zero(b)
                                      ? " (write 0. for a zero that stands for a real number)"
                                      : ""));
    return let(RCompute::Select, {expr_of(test, "if"), expr_of(a, "if"), expr_of(b, "if")}, ta);
  }
  if (is_structure(a) && is_structure(b) && as_structure(a)->up == as_structure(b)->up &&
      as_structure(a)->len == as_structure(b)->len) {
    Structure *x = as_structure(a), *y = as_structure(b);
    gcvec<Value> items;
    for (size_t i = 0; i < x->len; ++i)
      items.push_back(select_values(test, x->items[i], y->items[i]));
    return make_structure_from(x->up, items.data(), items.size());
  }
  if (is_pair(a) && is_pair(b))
    return cons(select_values(test, car(a), car(b)), select_values(test, cdr(a), cdr(b)));
  if (is_differential(a) || is_differential(b)) return select_differentials(test, a, b);
  RtList *ra = as_rtlist(a), *rb = as_rtlist(b);
  if (ra && rb && ra->list == rb->list && ra->reversed == rb->reversed)
    return make_rtlist(ra->list, ra->reversed, false, select_values(test, ra->start, rb->start),
                       select_values(test, ra->end, rb->end));
  cannot_compile(here(), "the alternatives of a test on a value known only at run time give " +
                             describe(a) + " and " + describe(b) +
                             ", which cannot be chosen between at run time");
}

namespace {

// Evaluate one alternative under a run-time test.
Value speculate(const std::function<Value()> &alternative) {
  if (g_build->branch_depth >= kMaxBranchDepth)
    cannot_compile(here(), "a loop or recursion whose end depends on a value known only at run "
                           "time");
  if (++g_build->branch_evaluations > kMaxBranchEvaluations)
    cannot_compile(here(), "more than " + std::to_string(kMaxBranchEvaluations) +
                               " alternatives under tests on run-time values: the program "
                               "unfolds too much (a loop whose arguments change shape, such as "
                               "a list that grows, cannot become a C loop and is unfolded)");
  ++g_build->branch_depth;
  try {
    Value v = alternative();
    --g_build->branch_depth;
    return v;
  } catch (...) {
    --g_build->branch_depth;
    throw;
  }
}

// Evaluate one alternative into its own block of statements, then undo
// its assignments to globals (recorded in *log).
Value alternative(std::vector<RStmt> &block, gcvec<Assignment> &log,
                  const std::function<Value()> &eval_it) {
  g_build->blocks.push_back(&block);
  g_build->undo.push_back(&log);
  g_build->undo_serials.push_back(g_frame_serial);
  auto restore = [&] {
    g_build->blocks.pop_back();
    g_build->undo.pop_back();
    g_build->undo_serials.pop_back();
    for (auto a = log.rbegin(); a != log.rend(); ++a) {
      a->after = *a->place;
      *a->place = a->before;
    }
  };
  try {
    Value v = speculate(eval_it);
    restore();
    return v;
  } catch (...) {
    restore();
    throw;
  }
}

// Both alternatives of a test on a run-time truth value: their statements
// become a C if/else, their values and the globals they assign are selected
// between after it.
Value branch(Value test, const std::function<Value()> &then_fn,
             const std::function<Value()> &else_fn) {
  std::vector<RStmt> then_block, else_block;
  gcvec<Assignment> then_log, else_log;
  Value a = alternative(then_block, then_log, then_fn);
  Value b = alternative(else_block, else_log, else_fn);
  bool calls = block_calls(then_block) || block_calls(else_block);
  if (!g_build->undo.empty()) { // an enclosing alternative undoes what these did, too
    for (const auto *log : {&then_log, &else_log})
      for (const Assignment &x : *log)
        log_assignment(Assignment{x.place, x.before, x.before, x.serial});
  }
  if (!then_block.empty() || !else_block.empty()) {
    RStmt s{RKind::If};
    s.args = {expr_of(test, "if")};
    s.then_body = std::move(then_block);
    s.else_body = std::move(else_block);
    current_block().push_back(std::move(s));
  }
  // A global either alternative assigned: the value it has after each.
  std::vector<Value *> assigned;
  for (const auto *log : {&then_log, &else_log})
    for (const Assignment &x : *log)
      if (std::find(assigned.begin(), assigned.end(), x.place) == assigned.end())
        assigned.push_back(x.place);
  for (Value *g : assigned) {
    bool is_cell = cell_of(g) >= 0 || list_cell_of(g) >= 0;
    if (is_cell) calls = true; // read it again after the if
    Value after_then = *g, after_else = *g;
    for (const Assignment &x : then_log)
      if (x.place == g) after_then = x.after;
    for (const Assignment &x : else_log)
      if (x.place == g) after_else = x.after;
    if (list_cell_of(g) >= 0)
      for (Value after : {after_then, after_else})
        if (!eq(after, *g) && !is_whole_list(after))
          cannot_compile(here(), "set! of a variable holding a list of run-time length to " +
                                     describe(after) +
                                     " under a test on a value known only at run time");
    Value merged = is_cell ? *g : select_values(test, after_then, after_else);
    uint32_t serial = 0;
    for (const auto *log : {&then_log, &else_log})
      for (const Assignment &x : *log)
        if (x.place == g) serial = x.serial;
    log_assignment(Assignment{g, *g, merged, serial});
    *g = merged;
  }
  if (calls) read_cells();
  return select_values(test, a, b);
}

// An assignment of v to *place (a global's value or a local variable's
// slot) named `name`. `outer`: the variable lives outside the procedure
// being traced for run time, so its value must persist from one run-time
// call to the next: a cell. `may_create`: it may become one here.
Value assign(Value *place, const std::string &name, Value v, SrcLoc loc, bool outer,
             bool may_create, Frame *frame) {
  if (outer && is_pair(v) && eq(cdr(v), *place)) { // (set! l (cons x l)) on a run-time list
    Value l = push_onto_list(place, name, car(v), loc, may_create, frame, false);
    log_assignment(Assignment{place, *place, l, frame ? frame->serial : 0});
    return l;
  }
  if (!outer && is_pair(v) && eq(cdr(v), *place) && grows_in_loop(frame)) {
    Value l = push_onto_list(place, name, car(v), loc, true, frame, true);
    log_assignment(Assignment{place, *place, l, frame ? frame->serial : 0});
    return l;
  }
  log_assignment(Assignment{place, *place, v, frame ? frame->serial : 0});
  int cell = cell_of(place);
  if (!outer && list_cell_of(place) >= 0) return v; // a new list for the next primitive
  if (!outer) {
    if (cell < 0) return v; // an ordinary assignment at compile time
    if (!is_scalar(v))
      cannot_compile(loc, "set! of " + name + " to " + describe(v) +
                              ": a procedure run at run time assigns it, so it must hold a number");
    if (scalar_type(v) == RType::Real) g_build->program.cells[cell].type = RType::Real;
    set_cell(cell, v);
    return v;
  }
  if (!is_scalar(v) || !is_scalar(*place))
    cannot_compile(loc, "set! of " + name + " to " + describe(v) +
                            " inside a procedure that runs at run time (a variable it keeps "
                            "from one call to the next can hold a number, not " +
                            describe(is_scalar(v) ? *place : v) + ")");
  if (cell < 0) {
    if (!may_create)
      cannot_compile(loc,
                     "set! of " + name + " inside a procedure run by another run-time procedure");
    g_build->program.cells.push_back(RCell{place, name, scalar_type(*place)});
    g_build->cell_initialized.push_back(false);
    if (frame) g_build->cell_frames.push_back(frame);
    throw Retrace{};
  }
  RCell &c = g_build->program.cells[cell];
  RType t = scalar_type(v);
  if (t != c.type) {
    if (c.type == RType::Boolean || t == RType::Boolean)
      cannot_compile(loc, "set! of " + name + " to a truth value and a number");
    if (c.type == RType::Integer) {
      c.type = RType::Real; // counts widen to reals: trace again with real reads
      throw Retrace{};
    }
  }
  set_cell(cell, v);
  return v;
}

} // namespace

// Only a truth value can be false: a run-time number is true, as every number is.
bool hook_dynamic_test(Value test) {
  return is_dynamic_boolean(test);
}

Value hook_branch(Value test, Node *then, Node *else_, Frame *env) {
  return branch(
      test, [&] { return eval(then, env); },
      [&] { return else_ ? eval(else_, env) : Value::unspecified(); });
}

Value hook_logic(Value test, Node *n, uint32_t from, bool is_and, Frame *env) {
  auto rest = [&] { return eval_logic_from(n, from, env); };
  if (is_and) return branch(test, rest, [] { return Value::boolean(false); });
  return branch(
      test, [] { return Value::boolean(true); }, rest);
}

Value hook_set_global(Symbol *s, Value v, SrcLoc loc) {
  return assign(&s->global, "the global variable " + s->name, v, loc, g_build->open.size() > 1,
                g_build->open.size() == 2, nullptr);
}

Value hook_set_local(Frame *f, uint32_t index, Value v, SrcLoc loc) {
  // Frames made before the innermost traced procedure began belong to its
  // callers: state kept across run-time calls.
  bool outer = g_build->open.size() > 1 && !made_since(f->serial, g_build->function_serials.back());
  bool may_create = g_build->open.size() == 2;
  return assign(&f->slots[index], "a local variable", v, loc, outer, may_create, f);
}

// ---- mutation of objects made before a traced procedure was called ----------------------
//
// A procedure traced for run time runs once, at compile time: a pair,
// vector or string it did not make would be changed once instead of at
// each call (and might keep a run-time value), and a promise made outside
// it would be forced during the trace, its effects traced into the
// procedure. Both are refused; what the procedure makes for itself it may
// change as it likes.

namespace {

[[noreturn]] void refuse_outer(const char *who, const char *what) {
  cannot_compile(here(), std::string(who) + " of " + what +
                             " made outside the procedure traced for run time (the procedure "
                             "runs once, while compiling)");
}

// Refuse who's change of v (a pair, a vector or a string) if v was made
// before the innermost traced procedure was called.
void check_owned(Value v, const char *who) {
  if (g_build->open.size() <= 1) return;
  uint32_t start = g_build->function_serials.back();
  if (v.is(Tag::Vector) && !made_since(v.vector()->serial, start)) refuse_outer(who, "a vector");
  if (v.is(Tag::Pair) && !made_since(v.pair()->serial, start)) refuse_outer(who, "a pair");
  if (v.is(Tag::String)) refuse_outer(who, "a string"); // strings keep no serial
}

// set-car!, vector-set!, ...: the first argument is what changes.
template <const char *Name> Value P_changes_first(Value *a, int n) {
  if (n > 0) check_owned(a[0], Name);
  return call_original(Name, a, n);
}

// append! changes the last pair of each list but the last.
Value P_append_bang(Value *a, int n) {
  for (int i = 0; i + 1 < n && g_build->open.size() > 1; ++i) {
    Value last = a[i];
    for (long k = 0; is_pair(last) && is_pair(cdr(last)) && k < 100000000; ++k)
      last = cdr(last);
    check_owned(last, "append!");
  }
  return call_original("append!", a, n);
}

constexpr char kSetCar[] = "set-car!";
constexpr char kSetCdr[] = "set-cdr!";
constexpr char kVectorSet[] = "vector-set!";
constexpr char kVectorFill[] = "vector-fill!";
constexpr char kVectorCopy[] = "vector-copy!";
constexpr char kStringSet[] = "string-set!";

Value P_with_output_to_string(Value *a, int n) {
  g_build->capture_depths.push_back(g_build->open.size());
  try {
    Value v = call_original("with-output-to-string", a, n);
    g_build->capture_depths.pop_back();
    return v;
  } catch (...) {
    g_build->capture_depths.pop_back();
    throw;
  }
}

} // namespace

// Output of a traced procedure into a string that a with-output-to-string
// outside it captures: the text would be captured once, while compiling.
void hook_capture() {
  if (!g_build->capture_depths.empty() && g_build->open.size() > g_build->capture_depths.back())
    cannot_compile(here(), "output of a procedure traced for run time into the string of a "
                           "with-output-to-string outside it");
}

void hook_forcing(Value promise) {
  if (g_build->open.size() <= 1) return;
  Frame *env = promise.as<Promise>()->env;
  if (!env || !made_since(env->serial, g_build->function_serials.back()))
    refuse_outer("forcing", "a promise");
}

// What this file specializes (the table is pe/specialized.cpp).
const PrimFn p_set_car = P_changes_first<kSetCar>, p_set_cdr = P_changes_first<kSetCdr>,
             p_vector_set = P_changes_first<kVectorSet>,
             p_vector_fill = P_changes_first<kVectorFill>,
             p_vector_copy = P_changes_first<kVectorCopy>,
             p_string_set = P_changes_first<kStringSet>, p_append_bang = P_append_bang,
             p_with_output_to_string = P_with_output_to_string;

} // namespace sicm::build
