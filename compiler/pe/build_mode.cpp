// `sicm build`: the evaluator's primitives and hooks that turn a run into a
// residual program (see codegen/residual.hpp for the idea).
//
// A BuildSession (begin_build_mode, below) rebinds the primitives whose
// meaning changes (all listed in pe/specialized.cpp's table), until it ends
// (end_build_mode puts them back): the numerical primitives record a
// statement and return fresh run-time values; plots record their
// statements; comparisons, floor, max and min of run-time values become
// statements; printing names the run-time values it prints.
// The evaluator's branch hooks make `if`, `and` and `or` on a run-time truth
// value evaluate both alternatives and select between their values at run
// time. Everything else runs as it always does, at compile time.
//
// What cannot be left for run time is a compile error ("cannot compile")
// naming the construct, its place in the source, and that `sicm run`
// interprets it:
//   - an effect (output, a plot mark, a numerical primitive, set! of a
//     global) under a test on a run-time value: both alternatives are
//     evaluated, so an effect would happen whichever way the test goes;
//   - a loop or recursion whose exit depends on a run-time value (it would
//     unfold without end; see kMaxBranchDepth);
//   - set! of a global variable inside a procedure traced for run time (the
//     procedure runs once at compile time, not each time it is called) to
//     anything but a number or truth value (a cell) or (cons x l) with l
//     the variable's list (a run-time list; see "lists whose length is
//     known only at run time" in pe/lists.cpp);
//   - a run-time value where a static one is needed (a frame's bounds, a
//     list index) or that escapes the procedure it was computed in.
//
// Loops whose iterations do run-time work are unrolled at compile time up to
// two named limits (base/limits.hpp, flags of sicm build), past which they
// are generalized into C loops instead (never an error: see
// "generalization" in pe/loops.cpp):
//   kMaxUnrolledElements   = 32  --max-unrolled-elements: map and for-each
//                                over a longer list of inexact numbers;
//   kMaxUnrolledIterations = 64  --max-unrolled-iterations: a named procedure
//                                called with known arguments that calls
//                                itself more often.
//
// The code is in these files, which share what pe/state.hpp declares:
//   specialized.cpp the one table of the primitives a build rebinds, with
//                   the function each means (defined in the files below)
//   build_mode.cpp  run-time values, statements, cells, output, tests of
//                   run-time values and BuildSession (this file)
//   numerics.cpp    tracing procedures into functions; the numerical
//                   primitives (integrals, minimizers, roots, state
//                   advancers, evolve)
//   plots.cpp       frame, plot-point, plot-line, graphics-close
//   branches.cpp    tests on run-time values (if, and, or), set!, and the
//                   mutations a traced procedure may not make
//   loops.cpp       loops left for run time: named procedures called again
//                   with run-time arguments, generalization past the unroll
//                   limits, loops that start from known values
//   lists.cpp       lists whose length is known only at run time
//   parallel.cpp    parallel-map and parallel-for-each
//   for_run.cpp     sicm run's use of all this: bisect's function compiled
#include "pe/build.hpp"

#include <algorithm>
#include <functional>
#include <string>
#include <unordered_map>

#include "algebra/differential.hpp"
#include "algebra/generic.hpp"
#include "algebra/linear_solve.hpp"
#include "algebra/structure.hpp"
#include "base/limits.hpp"
#include "base/number.hpp"
#include "base/primitive.hpp"
#include "builtins/parameter.hpp"
#include "codegen/state_shape.hpp"
#include "eval/core.hpp"
#include "eval/interp.hpp"
#include "eval/procedure.hpp"
#include "pe/specialized.hpp"
#include "pe/state.hpp"
#include "print/printer.hpp"

namespace sicm::build {

namespace {

const char kMarkerPrefix[] = "__sicm_rt";
const char kMarkerSuffix[] = "__";

} // namespace

[[noreturn]] void cannot_compile(SrcLoc loc, const std::string &what) {
  throw Error(ErrorKind::Syntax, ErrorCause::CannotCompile, loc, "cannot compile: " + what,
              kCannotCompileNote);
}

BuildState *g_build = nullptr;

SrcLoc here() {
  SrcLoc loc = current_call_loc();
  return loc.known() ? loc : current_toplevel_loc();
}

RFunction &current() {
  return g_build->program.functions[g_build->open.back()];
}

// Where statements go: the innermost open function's body, or the block of
// an alternative under a run-time test being evaluated (owned by
// hook_branch's frame). Function bodies are found by index: the function
// vector grows while they are open.

std::vector<RStmt> &current_block() {
  std::vector<RStmt> *b = g_build->blocks.empty() ? nullptr : g_build->blocks.back();
  return b ? *b : current().body;
}

// ---- run-time values ----------------------------------------------------------------

namespace {

void write_rtlist(std::string &out, const void *, bool) {
  out += "#[list of run-time length]";
}

const OpaqueKind kRtListKind = {"run-time-list", write_rtlist, nullptr};

// Does the expression mention a residual variable? (Memoized: the arena
// only grows and nodes never change.)
bool expr_is_dynamic(ExprId root) {
  std::vector<uint8_t> &memo = g_build->dynamic_memo;
  if (root < memo.size() && memo[root] != 0) return memo[root] == 2;
  bool dynamic = false;
  const ExprNode &n = expr_node(root);
  switch (n.kind) {
  case ExprKind::Rational:
  case ExprKind::Flonum: break;
  case ExprKind::Symbol: dynamic = g_build->var_ids.count(n.sym) > 0; break;
  case ExprKind::Apply:
  case ExprKind::Call: {
    dynamic = n.kind == ExprKind::Call && expr_is_dynamic(n.head);
    const ExprId *args = expr_args(root);
    for (uint32_t i = 0; i < n.nargs && !dynamic; ++i)
      dynamic = expr_is_dynamic(args[i]);
    break;
  }
  }
  if (memo.size() <= root) memo.resize(expr_count() + 1024, 0);
  memo[root] = dynamic ? 2 : 1;
  return dynamic;
}

// How a number, truth value or run-time value would be printed: an
// expression of counts (exact integers combined by + and *) is a count.
RType expr_type(ExprId id) {
  std::vector<uint8_t> &memo = g_build->type_memo;
  if (id < memo.size() && memo[id] != 0) return static_cast<RType>(memo[id] - 1);
  const ExprNode &n = expr_node(id);
  RType type = RType::Real;
  switch (n.kind) {
  case ExprKind::Rational: type = expr_is_exact_integer(id) ? RType::Integer : RType::Real; break;
  case ExprKind::Flonum: break;
  case ExprKind::Symbol: {
    auto it = g_build->var_ids.find(n.sym);
    if (it != g_build->var_ids.end()) type = g_build->program.vars[it->second].type;
    break;
  }
  case ExprKind::Apply:
    if (n.op == Op::Add || n.op == Op::Mul) {
      type = RType::Integer;
      const ExprId *args = expr_args(id);
      for (uint32_t i = 0; i < n.nargs && type == RType::Integer; ++i)
        if (expr_type(args[i]) != RType::Integer) type = RType::Real;
    }
    break;
  case ExprKind::Call: break;
  }
  if (memo.size() <= id) memo.resize(expr_count() + 1024, 0);
  memo[id] = static_cast<uint8_t>(static_cast<uint8_t>(type) + 1);
  return type;
}

} // namespace

Value new_var(RType type, const std::string &name) {
  int id = static_cast<int>(g_build->program.vars.size());
  Value sym = make_uninterned_symbol(
      name.empty() ? kMarkerPrefix + std::to_string(id) + kMarkerSuffix : name);
  g_build->program.vars.push_back(RVar{sym.symbol(), type, id, g_build->open.back()});
  g_build->var_ids[sym.symbol()] = id;
  return sym;
}

int var_of(Value v) {
  if (!v.is(Tag::Symbol)) return -1;
  auto it = g_build->var_ids.find(v.symbol());
  return it == g_build->var_ids.end() ? -1 : it->second;
}

RtList *as_rtlist(Value v) {
  if (!v.is(Tag::Opaque) || v.as<Opaque>()->kind != &kRtListKind) return nullptr;
  return static_cast<RtList *>(v.as<Opaque>()->obj);
}

Value make_rtlist(int list, bool reversed, bool whole, Value start, Value end) {
  RtList *r = gc_new<RtList>(RtList{list, reversed, whole, start, end});
  return Value::object(Tag::Opaque, gc_new<Opaque>(Opaque{&kRtListKind, r}));
}

bool is_dynamic_scalar(Value v) {
  if (var_of(v) >= 0) return true;
  return v.is(Tag::Expr) && expr_is_dynamic(static_cast<ExprId>(v.i));
}

bool is_dynamic_boolean(Value v) {
  int id = var_of(v);
  return id >= 0 && g_build->program.vars[id].type == RType::Boolean;
}

bool contains_dynamic(Value v) {
  if (is_dynamic_scalar(v) || as_rtlist(v)) return true;
  if (is_structure(v)) {
    Structure *s = as_structure(v);
    for (size_t i = 0; i < s->len; ++i)
      if (contains_dynamic(s->items[i])) return true;
    return false;
  }
  if (is_pair(v)) return contains_dynamic(car(v)) || contains_dynamic(cdr(v));
  if (v.is(Tag::Vector)) {
    Vector *vec = v.vector();
    for (size_t i = 0; i < vec->len; ++i)
      if (contains_dynamic(vec->items[i])) return true;
  }
  return false;
}

// s with each run-time variable's marker written <run-time number>.
std::string without_markers(std::string s) {
  for (size_t m; (m = s.find(kMarkerPrefix)) != std::string::npos;) {
    size_t end = s.find(kMarkerSuffix, m + sizeof kMarkerPrefix - 1);
    if (end == std::string::npos) break;
    s.replace(m, end + sizeof kMarkerSuffix - 1 - m, "<run-time number>");
  }
  return s;
}

std::string describe(Value v) {
  std::string s = without_markers(write_string(v));
  if (s.size() > 60) s = s.substr(0, 60) + "...";
  return s;
}

// A number, a boolean or a run-time value as an expression node.
ExprId expr_of(Value v, const char *who) {
  if (is_number(v)) return expr_from_number(v);
  if (v.is(Tag::Bool)) return expr_integer(v.truthy() ? 1 : 0);
  if (var_of(v) >= 0) return expr_symbol(v.symbol());
  if (v.is(Tag::Expr) && expr_is_dynamic(static_cast<ExprId>(v.i))) return static_cast<ExprId>(v.i);
  cannot_compile(here(), std::string(who) + " needs a number here, not " + describe(v));
}

RType scalar_type(Value v) {
  if (v.is(Tag::Bool)) return RType::Boolean;
  int id = var_of(v);
  if (id >= 0) return g_build->program.vars[id].type;
  if (v.is(Tag::Fixnum) || v.is(Tag::Bignum)) return RType::Integer;
  if (v.is(Tag::Expr)) return expr_type(static_cast<ExprId>(v.i));
  return RType::Real;
}

bool is_scalar(Value v) {
  return is_number(v) || v.is(Tag::Bool) || is_dynamic_scalar(v);
}

// ---- statements ---------------------------------------------------------------------

void emit(RStmt s) {
  if (!s.loc.known()) s.loc = here();
  std::vector<RStmt> &body = current_block();
  if (s.kind == RKind::Text && !body.empty() && body.back().kind == RKind::Text) {
    body.back().text += s.text;
    return;
  }
  // A statement after a loop's "continue" in the same block: the recursive
  // call was not in tail position (its result is not the loop's), so the
  // call is not a loop (LoopAbort is caught by the loop attempt).
  if (!body.empty() && body.back().kind == RKind::Continue) throw_not_a_loop();
  note_residual_statement(s.loc); // --max-residual-size
  if (s.kind != RKind::Text) ++g_build->work;
  bool calls = s.callee >= 0 || s.monitor >= 0 || s.first_monitor >= 0;
  body.push_back(std::move(s));
  if (calls) read_cells(); // the call may have assigned them
}

// ---- cells: globals that procedures run at run time assign ----------------------------
//
// A set! of a global inside a traced procedure makes the global a cell (a C
// global): the procedure is traced again from the start, now reading the
// cell where it begins, and every function reads the cells again after each
// call that may have assigned them. Only numbers and truth values can live
// in a cell.

int cell_of(Value *place) {
  for (size_t i = 0; i < g_build->program.cells.size(); ++i)
    if (g_build->program.cells[i].place == place) return static_cast<int>(i);
  return -1;
}

void set_cell(int cell, Value v) {
  RStmt s{RKind::SetCell};
  s.cell = cell;
  s.args = {expr_of(v, "set!")};
  emit(std::move(s));
}

// Make every cell's global hold a fresh read of the cell in the current function.
void read_cells() {
  read_list_cells();
  for (size_t i = 0; i < g_build->program.cells.size(); ++i) {
    if (!g_build->cell_initialized[i]) continue;
    RStmt s{RKind::Let};
    s.compute = RCompute::ReadCell;
    s.cell = static_cast<int>(i);
    Value v = new_var(g_build->program.cells[i].type);
    s.var = var_of(v);
    current_block().push_back(std::move(s));
    *g_build->program.cells[i].place = v;
  }
}

// Run a numerical primitive, tracing it again whenever a traced procedure
// turns a global into a cell (or widens a cell from counts to reals).
Value with_retrace(const std::function<Value()> &body) {
  size_t depth = g_build->open.size();
  if (depth != 1) return body(); // the outermost primitive retraces
  // The primitive's call site: tracing its procedures moves the evaluator's
  // idea of the current call into them, and a retrace must not take that
  // for the primitive's place (its errors and sites name the call).
  const SrcLoc call = current_call_loc();
  for (;;) {
    Checkpoint mark;
    reset_call_loc(call);
    try {
      return body();
    } catch (const Retrace &) {
      mark.restore();
      for (size_t i = 0; i < g_build->program.cells.size(); ++i) {
        if (g_build->cell_initialized[i]) continue;
        g_build->cell_initialized[i] = true;
        set_cell(static_cast<int>(i), *g_build->program.cells[i].place);
      }
      init_list_cells();
    }
  }
}

bool is_cannot_compile(const Error &e) {
  return e.cause == ErrorCause::CannotCompile;
}

Value let(RCompute c, std::vector<ExprId> args, RType type) {
  Value v = new_var(type);
  RStmt s{RKind::Let};
  s.compute = c;
  s.args = std::move(args);
  s.var = var_of(v);
  emit(std::move(s));
  return v;
}

// ---- output ---------------------------------------------------------------------------

namespace {

// A run-time scalar as a variable (an expression gets a Let).
Value as_var(Value v) {
  // A variable printed as itself is written as its marker: a kernel input
  // (named x0 ...) is copied into a variable that has one.
  if (var_of(v) >= 0 && symbol_name(v).rfind(kMarkerPrefix, 0) == 0) return v;
  return let(RCompute::Expr, {expr_of(v, "printing")}, scalar_type(v)); // a sum of counts is one
}

// Output text; names of run-time variables in it (printed from a value
// prepared by prepare_for_print) become Print statements.
void residual_output(std::string_view s) {
  size_t pos = 0;
  while (pos < s.size()) {
    size_t m = s.find(kMarkerPrefix, pos);
    size_t digits = m == std::string_view::npos ? m : m + sizeof kMarkerPrefix - 1;
    size_t end = digits;
    while (end != std::string_view::npos && end < s.size() && s[end] >= '0' && s[end] <= '9')
      ++end;
    bool marker = m != std::string_view::npos && end > digits &&
                  s.substr(end, sizeof kMarkerSuffix - 1) == kMarkerSuffix;
    if (!marker) {
      size_t stop = m == std::string_view::npos ? s.size() : m + 1;
      RStmt t{RKind::Text};
      t.text = std::string(s.substr(pos, stop - pos));
      emit(std::move(t));
      pos = stop;
      continue;
    }
    if (m > pos) {
      RStmt t{RKind::Text};
      t.text = std::string(s.substr(pos, m - pos));
      emit(std::move(t));
    }
    RStmt p{RKind::Print};
    p.var = std::stoi(std::string(s.substr(digits, end - digits)));
    emit(std::move(p));
    pos = end + sizeof kMarkerSuffix - 1;
  }
}

// v with every run-time expression in it replaced by a variable, so that
// printing it prints variable names (markers) where numbers will be.
Value prepare_for_print(Value v) {
  if (is_dynamic_scalar(v)) return as_var(v);
  if (as_rtlist(v))
    cannot_compile(here(), "printing " + describe(v) +
                               ", a list whose length is known only at run time (print its "
                               "elements with for-each)");
  if (is_structure(v)) {
    if (!contains_dynamic(v)) return v;
    Structure *s = as_structure(v);
    gcvec<Value> items(s->items, s->items + s->len);
    for (Value &x : items)
      x = prepare_for_print(x);
    return make_structure_from(s->up, items.data(), items.size());
  }
  if (is_pair(v)) {
    if (!contains_dynamic(v)) return v;
    return cons(prepare_for_print(car(v)), prepare_for_print(cdr(v)));
  }
  if (v.is(Tag::Vector) && contains_dynamic(v)) {
    Vector *vec = v.vector();
    Value out = make_vector(vec->len, Value::fixnum(0));
    for (size_t i = 0; i < vec->len; ++i)
      out.vector()->items[i] = prepare_for_print(vec->items[i]);
    return out;
  }
  return v;
}

} // namespace

// ---- the primitives that are rebound ---------------------------------------------------

namespace {

PrimFn original(const char *name) {
  return g_build->original_fns.at(name);
}

// Printing primitives: prepare the value, then print it as always.
template <const char *Name> Value P_print(Value *a, int n) {
  gcvec<Value> args(a, a + n);
  if (n > 0) args[0] = prepare_for_print(args[0]);
  return call_original(Name, args.data(), n);
}
constexpr char kDisplay[] = "display";
constexpr char kWrite[] = "write";
constexpr char kWriteLine[] = "write-line";
constexpr char kPp[] = "pp";
constexpr char kPrintExpression[] = "print-expression";
constexpr char kPe[] = "pe";

bool any_dynamic(Value *a, int n) {
  for (int i = 0; i < n; ++i)
    if (is_dynamic_scalar(a[i]) || is_dynamic_boolean(a[i])) return true;
  return false;
}

// x and y, either possibly a run-time truth value.
Value both(Value x, Value y, const char *who) {
  if (!is_dynamic_boolean(x) && !is_dynamic_boolean(y))
    return Value::boolean(x.truthy() && y.truthy());
  if (!is_dynamic_boolean(x)) return x.truthy() ? y : x;
  if (!is_dynamic_boolean(y)) return y.truthy() ? x : y;
  return let(RCompute::Select, {expr_of(x, who), expr_of(y, who), expr_integer(0)}, RType::Boolean);
}

// a0 op a1 op a2 ...: the conjunction of the pairwise comparisons.
Value compare_chain(Value *a, int n, RCompute c, bool swap, const char *who) {
  Value result = Value::boolean(true);
  for (int i = 0; i + 1 < n; ++i) {
    Value x = a[swap ? i + 1 : i], y = a[swap ? i : i + 1];
    Value r;
    if (!is_dynamic_scalar(x) && !is_dynamic_scalar(y)) {
      Value pair[2] = {a[i], a[i + 1]};
      r = call_original(who, pair, 2);
    } else {
      r = let(c, {expr_of(x, who), expr_of(y, who)}, RType::Boolean);
    }
    result = i == 0 ? r : both(result, r, who);
  }
  return result;
}

// The arguments with each differential replaced by its finite part, which
// is what a comparison compares (algebra/comparison.cpp): a test of a
// differential on the state is a test of the state.
gcvec<Value> finite_parts(Value *a, int n) {
  gcvec<Value> out(a, a + n);
  for (Value &v : out)
    v = differential_finite_part(v);
  return out;
}

template <const char *Name, RCompute C, bool Swap> Value P_compare(Value *a, int n) {
  gcvec<Value> finite = finite_parts(a, n);
  if (!any_dynamic(finite.data(), n)) return call_original(Name, a, n);
  return compare_chain(finite.data(), n, C, Swap, Name);
}
constexpr char kLess[] = "<";
constexpr char kGreater[] = ">";
constexpr char kLessEq[] = "<=";
constexpr char kGreaterEq[] = ">=";
constexpr char kEqual[] = "=";

// A scalar's kind as eqv? sees it: a truth value, an exact number, an
// inexact one.
RType scalar_kind(Value v) {
  if (is_dynamic_scalar(v) || is_dynamic_boolean(v)) return scalar_type(v);
  if (v.is(Tag::Bool)) return RType::Boolean;
  return v.is(Tag::Flonum) ? RType::Real : RType::Integer;
}

// eq?, eqv? and equal? where run-time values are compared: two numbers at
// run time (a run-time number is never the same as anything not a number);
// equal? also walks pairs, structures and vectors, comparing the leaves
// pairwise. Without this the comparison would be of the expressions that
// stand for the values, and two lists of equal run-time numbers would be
// different at compile time.
Value same(Value a, Value b, bool deep, const char *who) {
  bool da = is_dynamic_scalar(a) || is_dynamic_boolean(a),
       db = is_dynamic_scalar(b) || is_dynamic_boolean(b);
  if (da || db) {
    // What kind of scalar each is, is known now: eqv? of an inexact number
    // (a run-time number is one, unless it counts) and an exact one is #f.
    if (!is_scalar(a) || !is_scalar(b) || scalar_kind(a) != scalar_kind(b))
      return Value::boolean(false);
    return let(RCompute::Equal, {expr_of(a, who), expr_of(b, who)}, RType::Boolean);
  }
  if (!deep || (!contains_dynamic(a) && !contains_dynamic(b))) {
    Value pair[2] = {a, b};
    return call_original(who, pair, 2);
  }
  if (as_rtlist(a) || as_rtlist(b))
    cannot_compile(here(), std::string(who) + " of a list whose length is known only at run time");
  if (is_pair(a) || is_pair(b)) {
    if (!is_pair(a) || !is_pair(b)) return Value::boolean(false);
    Value first = same(car(a), car(b), deep, who);
    if (!is_dynamic_boolean(first) && !first.truthy()) return first;
    return both(first, same(cdr(a), cdr(b), deep, who), who);
  }
  size_t la = 0, lb = 0;
  Value *x = container_items(a, &la), *y = container_items(b, &lb);
  if (!x || !y || la != lb || a.tag != b.tag) return Value::boolean(false);
  if (is_structure(a) && as_structure(a)->up != as_structure(b)->up) return Value::boolean(false);
  Value result = Value::boolean(true);
  for (size_t i = 0; i < la; ++i)
    result = both(result, same(x[i], y[i], deep, who), who);
  return result;
}

template <const char *Name, bool Deep> Value P_same(Value *a, int n) {
  if (!contains_dynamic(a[0]) && !contains_dynamic(a[1])) return call_original(Name, a, n);
  return same(a[0], a[1], Deep, Name);
}
constexpr char kEqP[] = "eq?";
constexpr char kEqvP[] = "eqv?";
constexpr char kEqualP[] = "equal?";

template <const char *Name, RCompute C, bool Swap> Value P_sign_test(Value *a, int n) {
  // zero? of a differential is not a test of its finite part (scmutils'
  // diff:zero? asks whether every coefficient is 0): generic arithmetic's.
  Value x = C == RCompute::Equal ? a[0] : differential_finite_part(a[0]);
  if (!any_dynamic(&x, 1)) return call_original(Name, a, n);
  Value args[2] = {x, Value::fixnum(0)};
  return compare_chain(args, 2, C, Swap, Name);
}
constexpr char kZero[] = "zero?";
constexpr char kPositive[] = "positive?";
constexpr char kNegative[] = "negative?";

template <const char *Name, RCompute C> Value P_unary(Value *a, int n) {
  if (!any_dynamic(a, n)) return call_original(Name, a, n);
  return let(C, {expr_of(a[0], Name)}, RType::Real);
}
constexpr char kFloor[] = "floor";
constexpr char kRound[] = "round";
constexpr char kTruncate[] = "truncate";

// max or min of arguments among which are differentials whose finite parts
// are known only at run time: the argument whose finite part is chosen,
// selected at run time (algebra/comparison.cpp says what is chosen), with
// every finite part inexact, since one is.
Value choose_differential(Value *a, int n, bool max) {
  gcvec<Value> args(a, a + n);
  for (Value &v : args) {
    Value f = differential_finite_part(v);
    if (is_number(f) && !f.is(Tag::Flonum)) v = with_finite_part(v, num_exact_to_inexact(f));
    if (is_number(v) && !v.is(Tag::Flonum)) v = num_exact_to_inexact(v);
  }
  Value best = args[0];
  for (int i = 1; i < n; ++i) {
    // max: a later argument replaces the best one if the best is less.
    Value pair[2] = {differential_finite_part(max ? best : args[i]),
                     differential_finite_part(max ? args[i] : best)};
    Value test = compare_chain(pair, 2, RCompute::Less, false, "<");
    if (!is_dynamic_boolean(test))
      best = test.truthy() ? args[i] : best;
    else
      best = select_values(test, args[i], best);
  }
  return best;
}

// abs or magnitude of a differential whose finite part is known only at
// run time: x or -x, chosen at run time by the sign of that part, as
// algebra/differential.cpp chooses it for a number (scmutils' diff:abs), so
// its coefficients keep their kinds where a value may be printed. Where the
// part is 0 this gives x (sicm run's interpreter stops: no derivative
// there). A system derivative is traced as sicm run traces its kernels, with
// the slope x/|x| of generic arithmetic (g_build->doubles_only), so that
// both compile the same kernel.
template <const char *Name> Value P_abs(Value *a, int n) {
  Value f = differential_finite_part(a[0]);
  if (!is_differential(a[0]) || !is_dynamic_scalar(f) || g_build->doubles_only > 0)
    return call_original(Name, a, n);
  Value pair[2] = {f, Value::fixnum(0)};
  Value negative = compare_chain(pair, 2, RCompute::Less, false, "<");
  return select_values(negative, g_neg(a[0]), a[0]);
}
constexpr char kAbs[] = "abs";
constexpr char kMagnitude[] = "magnitude";

template <const char *Name, RCompute C> Value P_fold(Value *a, int n) {
  gcvec<Value> finite = finite_parts(a, n);
  if (!any_dynamic(finite.data(), n)) return call_original(Name, a, n);
  for (int i = 0; i < n; ++i)
    if (is_differential(a[i])) return choose_differential(a, n, C == RCompute::Max);
  Value acc = a[0];
  for (int i = 1; i < n; ++i)
    acc = let(C, {expr_of(acc, Name), expr_of(a[i], Name)}, RType::Real);
  return acc;
}
constexpr char kMax[] = "max";
constexpr char kMin[] = "min";

// The clocks are read when the program runs, not when it is compiled.
Value P_real_time(Value *, int) {
  return let(RCompute::RealTime, {}, RType::Real);
}
Value P_runtime(Value *, int) {
  return let(RCompute::RunTime, {}, RType::Real);
}

// A parameter stays a run-time value: ./prog --param name=value sets it;
// sicm build --fix name=value makes it that constant instead, so that terms
// it zeroes fold away.
Value P_parameter(Value *a, int) {
  if (!is_symbol(a[0])) wrong_type(a[0], 1, "parameter");
  if (!is_number(a[1])) wrong_type(a[1], 2, "parameter");
  declare_parameter(symbol_name(a[0]));
  double fixed;
  if (fixed_parameter(symbol_name(a[0]), &fixed)) return Value::flonum(fixed);
  if (g_build->open.size() > 1)
    cannot_compile(here(), "a parameter declared inside a procedure that runs at run time "
                           "(declare it at top level)");
  const std::string &name = symbol_name(a[0]);
  std::vector<std::string> &names = g_build->program.parameters;
  if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
  RStmt s{RKind::Let};
  s.compute = RCompute::Param;
  s.text = name;
  s.args = {expr_from_number(a[1])};
  Value v = new_var(RType::Real);
  s.var = var_of(v);
  emit(std::move(s));
  return v;
}

// A number drawn while compiling is the one sicm run draws only where the
// program runs once and in order: not in a procedure traced for run time
// (which runs at each call), under a test on a run-time value (both
// alternatives are evaluated, so every later draw would differ) or in a
// loop left for run time (its body is evaluated once).
Value P_random(Value *a, int n) {
  const char *where = g_build->open.size() > 1    ? "in a procedure traced for run time"
                      : g_build->branch_depth > 0 ? "under a test on a value known only at run time"
                      : !g_build->loops.empty()   ? "in a loop left for run time"
                                                  : nullptr;
  if (where)
    cannot_compile(here(), std::string("random numbers drawn ") + where +
                               " (they would be drawn once, while compiling)");
  return call_original("random", a, n);
}

Value P_not(Value *a, int n) {
  if (is_dynamic_boolean(a[0])) return let(RCompute::Not, {expr_of(a[0], "not")}, RType::Boolean);
  return call_original("not", a, n);
}

// A run-time value is a real number at run time: a flonum, or an exact
// non-negative integer for a count (minimize's iterations).
template <const char *Name> Value P_number_test(Value *a, int n) {
  if (!is_dynamic_scalar(a[0])) return call_original(Name, a, n);
  int v = var_of(a[0]);
  bool count = v >= 0 && g_build->program.vars[v].type == RType::Integer;
  std::string_view name = Name;
  if (name == "number?" || name == "real?") return Value::boolean(true);
  if (name == "inexact?") return Value::boolean(!count);
  return Value::boolean(count); // exact?, integer?, exact-integer?, ...
}
constexpr char kNumberP[] = "number?";
constexpr char kRealP[] = "real?";
constexpr char kInexactP[] = "inexact?";
constexpr char kExactP[] = "exact?";
constexpr char kIntegerP[] = "integer?";
constexpr char kExactIntegerP[] = "exact-integer?";
constexpr char kExactNonnegP[] = "exact-nonnegative-integer?";
constexpr char kExactRationalP[] = "exact-rational?";

template <const char *Name> Value P_identity_on_dynamic(Value *a, int n) {
  if (is_dynamic_scalar(a[0])) return a[0];
  return call_original(Name, a, n);
}
// Division, roots, logarithms and powers of run-time values remember the
// call that made them (ResidualProgram::op_sites): the executable reports
// a division by zero at the `/`, as sicm run does, not at the statement
// that computes the expression it is in.
template <const char *Name> Value P_located(Value *a, int n) {
  Value r = call_original(Name, a, n);
  if (is_dynamic_scalar(r)) g_build->program.op_sites.emplace(expr_of(r, Name), current_call_loc());
  return r;
}
constexpr char kDivide[] = "/";
constexpr char kSqrt[] = "sqrt";
constexpr char kLog[] = "log";
constexpr char kAsin[] = "asin";
constexpr char kAcos[] = "acos";
constexpr char kExpt[] = "expt";

constexpr char kExactToInexact[] = "exact->inexact";
constexpr char kInexact[] = "inexact";

const DynamicBranchHooks kHooks = {hook_dynamic_test,   hook_branch,    hook_logic,
                                   hook_set_global,     hook_set_local, hook_call_closure,
                                   hook_apply_to_other, hook_forcing};

Value prepare_toplevel(Value v) {
  return prepare_for_print(v);
}

// An argument error's object that holds run-time numbers, written with
// markers that fail_here turns into printing (see RunTimeWriter).
std::string write_with_markers(Value v) {
  return written(prepare_for_print(v));
}

} // namespace

// What this file specializes (the table is pe/specialized.cpp).
const PrimFn p_display = P_print<kDisplay>, p_write = P_print<kWrite>,
             p_write_line = P_print<kWriteLine>, p_pp = P_print<kPp>,
             p_print_expression = P_print<kPrintExpression>, p_pe = P_print<kPe>;
const PrimFn p_less = P_compare<kLess, RCompute::Less, false>,
             p_greater = P_compare<kGreater, RCompute::Less, true>,
             p_less_eq = P_compare<kLessEq, RCompute::LessEq, false>,
             p_greater_eq = P_compare<kGreaterEq, RCompute::LessEq, true>,
             p_num_equal = P_compare<kEqual, RCompute::Equal, false>;
const PrimFn p_zero_p = P_sign_test<kZero, RCompute::Equal, false>,
             p_positive_p = P_sign_test<kPositive, RCompute::Less, true>,
             p_negative_p = P_sign_test<kNegative, RCompute::Less, false>;
const PrimFn p_floor = P_unary<kFloor, RCompute::Floor>, p_round = P_unary<kRound, RCompute::Round>,
             p_truncate = P_unary<kTruncate, RCompute::Truncate>,
             p_max = P_fold<kMax, RCompute::Max>, p_min = P_fold<kMin, RCompute::Min>,
             p_abs = P_abs<kAbs>, p_magnitude = P_abs<kMagnitude>, p_not = P_not;
const PrimFn p_eq_p = P_same<kEqP, false>, p_eqv_p = P_same<kEqvP, false>,
             p_equal_p = P_same<kEqualP, true>;
const PrimFn p_random = P_random, p_real_time = P_real_time, p_parameter = P_parameter,
             p_runtime = P_runtime;
const PrimFn p_number_p = P_number_test<kNumberP>, p_real_p = P_number_test<kRealP>,
             p_inexact_p = P_number_test<kInexactP>, p_exact_p = P_number_test<kExactP>,
             p_integer_p = P_number_test<kIntegerP>,
             p_exact_integer_p = P_number_test<kExactIntegerP>,
             p_exact_nonnegative_integer_p = P_number_test<kExactNonnegP>,
             p_exact_rational_p = P_number_test<kExactRationalP>;
const PrimFn p_divide = P_located<kDivide>, p_sqrt = P_located<kSqrt>, p_log = P_located<kLog>,
             p_asin = P_located<kAsin>, p_acos = P_located<kAcos>, p_expt = P_located<kExpt>;
const PrimFn p_exact_to_inexact = P_identity_on_dynamic<kExactToInexact>,
             p_inexact = P_identity_on_dynamic<kInexact>;

Value call_original(const char *name, Value *a, int n) {
  return original(name)(a, n);
}

void rebind(const char *name, int min, int max, PrimFn fn) {
  Symbol *s = intern(name).symbol();
  Stage stage = Stage::Pure;
  if (s->bound && s->global.is(Tag::Primitive)) {
    g_build->original_fns[name] = s->global.as<Primitive>()->fn;
    stage = s->global.as<Primitive>()->stage; // the build's version does the same kind of work
  }
  g_build->rebound.push_back(s);
  g_build->rebound_values.push_back(s->global);
  g_build->rebound_bound.push_back(s->bound);
  define_primitive(name, min, max, stage, fn);
}

} // namespace sicm::build

namespace sicm {

bool in_build_mode() {
  return build::g_build != nullptr;
}

namespace {

// Outside every traced function, alternative of a run-time test and loop
// left for run time: where an error is the program's, at that point.
bool at_program_top_level() {
  using namespace build;
  return g_build->open.size() == 1 && g_build->blocks.size() == 1 && g_build->branch_depth == 0 &&
         g_build->loops.empty();
}

// Rebind the primitives and install the evaluator's hooks so that what runs
// from now on records into state's program.
void begin_build_mode(build::BuildState *state) {
  using namespace build;
  SICM_ASSERT(!g_build); // one build at a time
  g_build = state;
  // Divisions by matrices of run-time values outside kernels compute as
  // the interpreter does (algebra/linear_solve.hpp).
  set_run_time_value_test(is_dynamic_scalar);
  g_build->bottom = Value::object(Tag::Opaque, gc_new<Opaque>(Opaque{&kBottomKind, nullptr}));
  RFunction main_fn;
  main_fn.id = 0;
  main_fn.parent = -1;
  main_fn.name = "main";
  g_build->program.functions.push_back(std::move(main_fn));
  g_build->open = {0};
  g_build->advancer_lambda.name = intern("state-advancer").symbol();
  g_build->evolver_lambda.name = intern("evolve").symbol();
  g_build->crossings_lambda.name = intern("crossings").symbol();

  for (const Specialization &p : specializations()) {
    Symbol *s = intern(p.name).symbol();
    if (p.only_over_a_primitive && !(s->bound && s->global.is(Tag::Primitive))) continue;
    rebind(p.name, p.min_args, p.max_args, p.fn);
  }

  set_output_hook(residual_output);
  set_capture_hook(hook_capture);
  set_print_preparer(prepare_toplevel);
  set_top_level_probe(at_program_top_level);
  set_run_time_writer(write_with_markers);
  g_dynamic_branch_hooks = &kHooks;
}

// Back to sicm run: the primitives and hooks as they were before begin_build_mode.
void end_build_mode() {
  using namespace build;
  for (size_t i = g_build->rebound.size();
       i-- > 0;) { // the first rebinding of a name holds the original
    g_build->rebound[i]->global = g_build->rebound_values[i];
    g_build->rebound[i]->bound = g_build->rebound_bound[i];
  }
  g_dynamic_branch_hooks = nullptr;
  set_output_hook(nullptr);
  set_capture_hook(nullptr);
  set_print_preparer(nullptr);
  set_run_time_value_test(nullptr);
  set_top_level_probe(nullptr);
  set_run_time_writer(nullptr);
  g_build = nullptr;
}

} // namespace

BuildSession::BuildSession() {
  void *memory = GC_MALLOC_UNCOLLECTABLE(sizeof(build::BuildState));
  if (!memory) throw std::bad_alloc();
  state_ = new (memory) build::BuildState();
  begin_build_mode(state_);
}

BuildSession::~BuildSession() {
  end_build_mode();
  state_->~BuildState();
  GC_FREE(state_);
}

ResidualProgram &BuildSession::program() {
  return state_->program;
}

void BuildSession::fail_here(const Error &e) {
  SICM_ASSERT(build::g_build == state_ && e.at_top_level);
  flush_output();                        // what the program printed before, in its place
  std::string message = format_error(e); // the bytes sicm run writes on stderr
  RStmt s{RKind::Fail};
  s.loc = e.loc;
  if (message.find(build::kMarkerPrefix) == std::string::npos) {
    s.text = std::move(message);
  } else { // numbers known at run time in it: printed into the message there
    RStmt capture{RKind::FailCapture};
    capture.loc = e.loc;
    build::emit(std::move(capture));
    build::residual_output(message);
  }
  build::emit(std::move(s));
}

std::string BuildSession::described(const std::string &message) {
  return build::without_markers(message);
}

} // namespace sicm
