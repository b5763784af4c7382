// `sicm build`: the evaluator's primitives and hooks that turn a run into a
// residual program (see codegen/residual.hpp for the idea).
//
// begin_build_mode() rebinds the primitives whose meaning changes: the
// numerical primitives record a statement and return fresh run-time values;
// plots record their statements; comparisons, floor, max and min of run-time
// values become statements; printing names the run-time values it prints.
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
//     known only at run time");
//   - a run-time value where a static one is needed (a frame's bounds, a
//     list index) or that escapes the procedure it was computed in.
//
// Loops whose iterations do run-time work are unrolled at compile time up to
// two named limits (eval/limits.hpp, flags of sicm build), past which they
// are generalized into C loops instead (never an error: see
// "generalization" below):
//   kMaxUnrolledElements   = 32  --max-unrolled-elements: map and for-each
//                                over a longer list of inexact numbers;
//   kMaxUnrolledIterations = 64  --max-unrolled-iterations: a named procedure
//                                called with known arguments that calls
//                                itself more often.
#include "eval/build.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "algebra/generic.hpp"
#include "algebra/linear_solve.hpp"
#include "algebra/structure.hpp"
#include "algebra/symbolic.hpp"
#include "codegen/emit_taylor.hpp"
#include "codegen/kernel_form.hpp"
#include "codegen/singular_factors.hpp"
#include "codegen/state_shape.hpp"
#include "codegen/trace.hpp"
#include "eval/core.hpp"
#include "eval/interp.hpp"
#include "eval/limits.hpp"
#include "eval/number.hpp"
#include "eval/numerics_defaults.hpp"
#include "eval/parameter.hpp"
#include "eval/plot.hpp"
#include "eval/primitive.hpp"
#include "eval/procedure.hpp"
#include "print/printer.hpp"

namespace sicm {

namespace {

// Nested tests on run-time values deeper than this are taken for a loop
// whose exit depends on a run-time value.
constexpr int kMaxBranchDepth = 48;
// Alternatives evaluated under such tests in one top-level form, at most.
constexpr long kMaxBranchEvaluations = 200000;

const char kMarkerPrefix[] = "__sicm_rt";
const char kMarkerSuffix[] = "__";

ResidualProgram *g_prog = nullptr;
std::vector<int> g_open;                    // functions being traced, innermost last
std::unordered_map<Symbol *, int> g_var_of; // residual variable of a symbol
int g_branch_depth = 0;
long g_branch_evaluations = 0;

[[noreturn]] void cannot_compile(SrcLoc loc, const std::string &what) {
  throw Error(ErrorKind::Syntax, loc, "cannot compile: " + what,
              "sicm build leaves only numerical work for run time; `sicm run` interprets this "
              "program");
}

SrcLoc here() {
  SrcLoc loc = current_call_loc();
  return loc.known() ? loc : current_toplevel_loc();
}

RFunction &current() {
  return g_prog->functions[g_open.back()];
}

// Where statements go: the innermost open function's body, or the block of
// an alternative under a run-time test being evaluated (owned by
// hook_branch's frame). Function bodies are found by index: the function
// vector grows while they are open.
std::vector<std::vector<RStmt> *> g_blocks; // null: the open function's body

std::vector<RStmt> &current_block() {
  std::vector<RStmt> *b = g_blocks.empty() ? nullptr : g_blocks.back();
  return b ? *b : current().body;
}

// ---- run-time values ----------------------------------------------------------------

Value new_var(RType type) {
  int id = static_cast<int>(g_prog->vars.size());
  Value sym = make_uninterned_symbol(kMarkerPrefix + std::to_string(id) + kMarkerSuffix);
  g_prog->vars.push_back(RVar{sym.symbol(), type, id, g_open.back()});
  g_var_of[sym.symbol()] = id;
  return sym;
}

int var_of(Value v) {
  if (!v.is(Tag::Symbol)) return -1;
  auto it = g_var_of.find(v.symbol());
  return it == g_var_of.end() ? -1 : it->second;
}

// A list built at run time (see "lists whose length is known only at run
// time" below): elements [start, end) of the runtime's list `list`, read
// forward from start (reversed: the order they were added) or backward from
// end - 1 (the order of a list built by consing onto its front). start and
// end are counts: exact integers or run-time values.
struct RtList {
  int list;
  bool reversed;
  bool whole; // the whole list as its variable holds it (read again after each call)
  Value start, end;
};

void write_rtlist(std::string &out, const void *, bool) {
  out += "#[list of run-time length]";
}

const OpaqueKind kRtListKind = {"run-time-list", write_rtlist, nullptr};

RtList *as_rtlist(Value v) {
  if (!v.is(Tag::Opaque) || v.as<Opaque>()->kind != &kRtListKind) return nullptr;
  return static_cast<RtList *>(v.as<Opaque>()->obj);
}

Value make_rtlist(int list, bool reversed, bool whole, Value start, Value end) {
  RtList *r = gc_new<RtList>(RtList{list, reversed, whole, start, end});
  return Value::object(Tag::Opaque, gc_new<Opaque>(Opaque{&kRtListKind, r}));
}

// Does the expression mention a residual variable? (Memoized: the arena
// only grows and nodes never change.)
bool expr_is_dynamic(ExprId root) {
  static std::unordered_map<ExprId, bool> memo;
  auto hit = memo.find(root);
  if (hit != memo.end()) return hit->second;
  bool dynamic = false;
  const ExprNode &n = expr_node(root);
  switch (n.kind) {
  case ExprKind::Rational:
  case ExprKind::Flonum: break;
  case ExprKind::Symbol: dynamic = g_var_of.count(n.sym) > 0; break;
  case ExprKind::Apply:
  case ExprKind::Call: {
    std::vector<ExprId> args = expr_arg_vector(root);
    if (n.kind == ExprKind::Call) args.push_back(n.head);
    for (ExprId a : args)
      if (expr_is_dynamic(a)) {
        dynamic = true;
        break;
      }
    break;
  }
  }
  memo[root] = dynamic;
  return dynamic;
}

bool is_dynamic_scalar(Value v) {
  if (var_of(v) >= 0) return true;
  return v.is(Tag::Expr) && expr_is_dynamic(static_cast<ExprId>(v.i));
}

bool is_dynamic_boolean(Value v) {
  int id = var_of(v);
  return id >= 0 && g_prog->vars[id].type == RType::Boolean;
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

std::string describe(Value v) {
  std::string s = write_string(v);
  for (size_t m; (m = s.find(kMarkerPrefix)) != std::string::npos;) {
    size_t end = s.find(kMarkerSuffix, m + sizeof kMarkerPrefix - 1);
    if (end == std::string::npos) break;
    s.replace(m, end + sizeof kMarkerSuffix - 1 - m, "<run-time number>");
  }
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

// How a number, truth value or run-time value would be printed: an
// expression of counts (exact integers combined by + and *) is a count.
RType expr_type(ExprId id) {
  const ExprNode &n = expr_node(id);
  switch (n.kind) {
  case ExprKind::Rational: return expr_is_exact_integer(id) ? RType::Integer : RType::Real;
  case ExprKind::Flonum: return RType::Real;
  case ExprKind::Symbol: {
    auto it = g_var_of.find(n.sym);
    return it == g_var_of.end() ? RType::Real : g_prog->vars[it->second].type;
  }
  case ExprKind::Apply:
    if (n.op == Op::Add || n.op == Op::Mul) {
      for (ExprId a : expr_arg_vector(id))
        if (expr_type(a) != RType::Integer) return RType::Real;
      return RType::Integer;
    }
    return RType::Real;
  case ExprKind::Call: return RType::Real;
  }
  return RType::Real;
}

RType scalar_type(Value v) {
  if (v.is(Tag::Bool)) return RType::Boolean;
  int id = var_of(v);
  if (id >= 0) return g_prog->vars[id].type;
  if (v.is(Tag::Fixnum) || v.is(Tag::Bignum)) return RType::Integer;
  if (v.is(Tag::Expr)) return expr_type(static_cast<ExprId>(v.i));
  return RType::Real;
}

bool is_scalar(Value v) {
  return is_number(v) || v.is(Tag::Bool) || is_dynamic_scalar(v);
}

// ---- statements ---------------------------------------------------------------------

void read_cells();
[[noreturn]] void throw_not_a_loop();
uint64_t g_work = 0; // statements recorded other than output text (see StaticWatch)

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
  if (s.kind != RKind::Text) ++g_work;
  bool calls = s.callee >= 0 || s.monitor >= 0;
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

struct Retrace {}; // thrown to trace the current numerical primitive again

std::vector<bool> g_cell_initialized;

int cell_of(Value *place) {
  for (size_t i = 0; i < g_prog->cells.size(); ++i)
    if (g_prog->cells[i].place == place) return static_cast<int>(i);
  return -1;
}

gcvec<Frame *> g_cell_frames; // keeps the frames of local cells alive (a scanned vector)
std::vector<uint32_t> g_function_serials; // g_frame_serial when each open function began

void set_cell(int cell, Value v) {
  RStmt s{RKind::SetCell};
  s.cell = cell;
  s.args = {expr_of(v, "set!")};
  emit(std::move(s));
}

void read_list_cells();
void init_list_cells();

// Make every cell's global hold a fresh read of the cell in the current function.
void read_cells() {
  read_list_cells();
  for (size_t i = 0; i < g_prog->cells.size(); ++i) {
    if (!g_cell_initialized[i]) continue;
    RStmt s{RKind::Let};
    s.compute = RCompute::ReadCell;
    s.cell = static_cast<int>(i);
    Value v = new_var(g_prog->cells[i].type);
    s.var = var_of(v);
    current_block().push_back(std::move(s));
    *g_prog->cells[i].place = v;
  }
}

// Run a numerical primitive, tracing it again whenever a traced procedure
// turns a global into a cell (or widens a cell from counts to reals).
Value with_retrace(const std::function<Value()> &body) {
  size_t depth = g_open.size();
  if (depth != 1) return body(); // the outermost primitive retraces
  size_t nfunctions = g_prog->functions.size(), nvars = g_prog->vars.size();
  // The primitive's call site: tracing its procedures moves the evaluator's
  // idea of the current call into them, and a retrace must not take that
  // for the primitive's place (its errors and sites name the call).
  const SrcLoc call = current_call_loc();
  for (;;) {
    size_t nbody = current().body.size();
    reset_call_loc(call);
    try {
      return body();
    } catch (const Retrace &) {
      for (size_t v = nvars; v < g_prog->vars.size(); ++v)
        g_var_of.erase(g_prog->vars[v].sym);
      g_prog->functions.resize(nfunctions);
      g_prog->vars.resize(nvars);
      std::vector<RStmt> &main_body = current().body;
      main_body.erase(main_body.begin() + static_cast<long>(nbody), main_body.end());
      for (size_t i = 0; i < g_prog->cells.size(); ++i) {
        if (g_cell_initialized[i]) continue;
        g_cell_initialized[i] = true;
        set_cell(static_cast<int>(i), *g_prog->cells[i].place);
      }
      init_list_cells();
    }
  }
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

// A run-time scalar as a variable (an expression gets a Let).
Value as_var(Value v) {
  if (var_of(v) >= 0) return v;
  return let(RCompute::Expr, {expr_of(v, "printing")}, RType::Real);
}

template <PrimFn F> Value retrying(Value *a, int n) {
  return with_retrace([&] { return F(a, n); });
}

template <NativeFn F> Value retrying_native(NativeProc *self, Value *a, int n) {
  return with_retrace([&] { return F(self, a, n); });
}

// ---- output ---------------------------------------------------------------------------

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

// ---- the primitives that are rebound ---------------------------------------------------

std::unordered_map<std::string, PrimFn> g_original;

PrimFn original(const char *name) {
  return g_original.at(name);
}

Value call_original(const char *name, Value *a, int n) {
  return original(name)(a, n);
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
    if (i == 0) {
      result = r;
    } else if (is_dynamic_boolean(result) || is_dynamic_boolean(r)) {
      result = let(RCompute::Select, {expr_of(result, who), expr_of(r, who), expr_integer(0)},
                   RType::Boolean);
    } else {
      result = Value::boolean(result.truthy() && r.truthy());
    }
  }
  return result;
}

template <const char *Name, RCompute C, bool Swap> Value P_compare(Value *a, int n) {
  if (!any_dynamic(a, n)) return call_original(Name, a, n);
  return compare_chain(a, n, C, Swap, Name);
}
constexpr char kLess[] = "<";
constexpr char kGreater[] = ">";
constexpr char kLessEq[] = "<=";
constexpr char kGreaterEq[] = ">=";
constexpr char kEqual[] = "=";

template <const char *Name, RCompute C, bool Swap> Value P_sign_test(Value *a, int n) {
  if (!any_dynamic(a, n)) return call_original(Name, a, n);
  Value args[2] = {a[0], Value::fixnum(0)};
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

template <const char *Name, RCompute C> Value P_fold(Value *a, int n) {
  if (!any_dynamic(a, n)) return call_original(Name, a, n);
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
  double fixed;
  if (fixed_parameter(symbol_name(a[0]), &fixed)) return Value::flonum(fixed);
  if (g_open.size() > 1)
    cannot_compile(here(), "a parameter declared inside a procedure that runs at run time "
                           "(declare it at top level)");
  const std::string &name = symbol_name(a[0]);
  std::vector<std::string> &names = g_prog->parameters;
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

Value P_not(Value *a, int n) {
  if (is_dynamic_boolean(a[0])) return let(RCompute::Not, {expr_of(a[0], "not")}, RType::Boolean);
  return call_original("not", a, n);
}

// A run-time value is a real number at run time: a flonum, or an exact
// non-negative integer for a count (minimize's iterations).
template <const char *Name> Value P_number_test(Value *a, int n) {
  if (!is_dynamic_scalar(a[0])) return call_original(Name, a, n);
  int v = var_of(a[0]);
  bool count = v >= 0 && g_prog->vars[v].type == RType::Integer;
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
constexpr char kExactToInexact[] = "exact->inexact";
constexpr char kInexact[] = "inexact";

bool container_items_of(Value v) {
  size_t len;
  return container_items(v, &len) != nullptr;
}

// ---- tracing procedures into functions ------------------------------------------------

std::vector<Value *> list_cell_places();
int list_cell_of(const Value *place);
bool is_whole_list(Value v);

// Opens a function for the duration of a trace.
class FunctionScope {
public:
  FunctionScope(const std::string &name) {
    RFunction f;
    f.id = static_cast<int>(g_prog->functions.size());
    f.parent = g_open.back();
    f.name = name;
    f.loc = here();
    g_prog->functions.push_back(std::move(f));
    g_open.push_back(g_prog->functions.back().id);
    g_blocks.push_back(nullptr);
    g_function_serials.push_back(g_frame_serial);
    saved_depth_ = g_branch_depth;
    g_branch_depth = 0; // a test inside the traced procedure is its own
    for (const RCell &c : g_prog->cells)
      saved_.push_back(*c.place);
    for (Value *place : list_cell_places())
      saved_lists_.push_back(place ? *place : Value::nil());
    read_cells();
  }
  ~FunctionScope() {
    g_open.pop_back();
    g_blocks.pop_back();
    g_function_serials.pop_back();
    g_branch_depth = saved_depth_;
    for (size_t i = 0; i < saved_.size() && i < g_prog->cells.size(); ++i)
      *g_prog->cells[i].place = saved_[i];
    std::vector<Value *> places = list_cell_places();
    for (size_t i = 0; i < saved_lists_.size() && i < places.size(); ++i)
      *places[i] = saved_lists_[i];
  }
  int id() const { return g_open.back(); }

private:
  int saved_depth_;
  gcvec<Value> saved_;       // the cells' globals as the caller sees them
  gcvec<Value> saved_lists_; // the list cells' variables
};

// A value shaped like `sample` (a number, or an up/down structure of them)
// whose leaves are fresh inputs of the current function.
Value input_like(Value sample) {
  gcvec<Value> leaves;
  state_leaves(sample, leaves);
  for (Value &leaf : leaves) {
    leaf = new_var(RType::Real);
    current().inputs.push_back(var_of(leaf));
  }
  return state_from_leaves(sample, leaves);
}

bool is_state_shape(Value v) {
  if (is_number(v) || is_dynamic_scalar(v)) return true;
  size_t len;
  Value *items = container_items(v, &len);
  if (!items || len == 0) return false;
  for (size_t i = 0; i < len; ++i)
    if (!is_state_shape(items[i])) return false;
  return true;
}

// The result leaves of a traced procedure as outputs, unsimplified: they
// keep the order of operations the interpreter follows (so a built program
// computes what `sicm run` computes), and expanding, say, (x - 2)^2 into
// x^2 - 4x + 4 would lose the accuracy a minimizer near 2 needs.
void set_outputs(Value result, const char *who) {
  gcvec<Value> leaves;
  if (!is_state_shape(result))
    cannot_compile(here(), std::string("the procedure passed to ") + who + " returns " +
                               describe(result) + ", not a number or a structure of numbers");
  state_leaves(result, leaves);
  for (Value leaf : leaves)
    current().outputs.push_back(expr_of(leaf, who));
}

std::string procedure_name(Value proc) {
  if (proc.is(Tag::Closure) && proc.as<Closure>()->lambda->name)
    return proc.as<Closure>()->lambda->name->name;
  return "anonymous";
}

// Trace a scalar function (integrand, objective, function with a root).
int trace_scalar(Value f, const char *who) {
  if (!is_procedure(f)) wrong_type(f, 1, who);
  FunctionScope scope(procedure_name(f));
  Value x = input_like(Value::flonum(0));
  Value r = apply_procedure(f, &x, 1);
  if (!is_number(r) && !is_dynamic_scalar(r))
    cannot_compile(here(), std::string("the procedure passed to ") + who + " returns " +
                               describe(r) + ", not a number");
  set_outputs(r, who);
  return scope.id();
}

// ---- numerical primitives ---------------------------------------------------------------

double static_number(Value *a, int n, int i, double fallback, const char *who) {
  if (i >= n || a[i].is(Tag::Default)) return fallback;
  if (!is_number(a[i])) {
    if (is_dynamic_scalar(a[i]))
      cannot_compile(here(), std::string(who) + "'s tolerance must be known at compile time");
    wrong_type(a[i], i + 1, who);
  }
  return to_double(a[i]);
}

ExprId limit_expr(Value v, const char *who) {
  if (is_symbol(v) && var_of(v) < 0) {
    const std::string &s = symbol_name(v);
    if (s == ":+infinity" || s == "+infinity") return expr_flonum(INFINITY);
    if (s == ":-infinity" || s == "-infinity") return expr_flonum(-INFINITY);
  }
  return expr_of(v, who);
}

Value P_definite_integral(Value *a, int n) {
  static const char who[] = "definite-integral";
  if (is_number(a[1]) && is_number(a[2]) && to_double(a[1]) == to_double(a[2]))
    return Value::fixnum(0); // as the interpreter: an exact 0 over an empty interval
  RStmt s{RKind::Integral};
  s.loc = here();
  s.args = {limit_expr(a[1], who), limit_expr(a[2], who)};
  s.number = static_number(a, n, 3, kIntegralTolerance, who);
  s.callee = trace_scalar(a[0], who);
  Value r = new_var(RType::Real);
  s.outs = {var_of(r)};
  emit(std::move(s));
  return r;
}

template <const char *Name> Value P_minimize(Value *a, int n) {
  RStmt s{RKind::Minimize};
  s.loc = here();
  s.args = {expr_of(a[1], Name), expr_of(a[2], Name)};
  s.number = static_number(a, n, 3, kMinimizeTolerance, Name);
  s.callee = trace_scalar(a[0], Name);
  Value x = new_var(RType::Real), fx = new_var(RType::Real), it = new_var(RType::Integer);
  s.outs = {var_of(x), var_of(fx), var_of(it)};
  emit(std::move(s));
  return list({x, fx, it});
}
constexpr char kMinimize[] = "minimize";
constexpr char kBrentMin[] = "brent-min";

Value P_multidimensional_minimize(Value *a, int n) {
  static const char who[] = "multidimensional-minimize";
  if (!is_procedure(a[0])) wrong_type(a[0], 1, who);
  bool is_list = !a[1].is(Tag::Vector);
  gcvec<Value> start;
  if (is_list) {
    if (list_length(a[1]) <= 0) wrong_type(a[1], 2, who);
    start = list_to_vector(a[1]);
  } else {
    Vector *v = a[1].vector();
    start.assign(v->items, v->items + v->len);
  }
  if (start.empty()) wrong_type(a[1], 2, who);
  RStmt s{RKind::Multimin};
  s.loc = here();
  for (Value x : start)
    s.args.push_back(expr_of(x, who));
  s.number = static_number(a, n, 2, kNelderTolerance, who);
  {
    FunctionScope scope(procedure_name(a[0]));
    gcvec<Value> xs;
    for (size_t i = 0; i < start.size(); ++i)
      xs.push_back(input_like(Value::flonum(0)));
    Value point;
    if (is_list) {
      point = list_from(xs.data(), xs.size());
    } else {
      point = make_vector(xs.size(), Value::fixnum(0));
      for (size_t i = 0; i < xs.size(); ++i)
        point.vector()->items[i] = xs[i];
    }
    Value r = apply_procedure(a[0], &point, 1);
    set_outputs(r, who);
    if (current().outputs.size() != 1)
      cannot_compile(here(), "the function passed to multidimensional-minimize must return one "
                             "number");
    s.callee = scope.id();
  }
  gcvec<Value> result;
  for (size_t i = 0; i < start.size(); ++i) {
    Value x = new_var(RType::Real);
    s.outs.push_back(var_of(x));
    result.push_back(x);
  }
  emit(std::move(s));
  if (is_list) return list_from(result.data(), result.size());
  Value v = make_vector(result.size(), Value::fixnum(0));
  for (size_t i = 0; i < result.size(); ++i)
    v.vector()->items[i] = result[i];
  return v;
}

Value P_find_root(Value *a, int n) {
  static const char who[] = "find-root";
  RStmt s{RKind::FindRoot};
  s.loc = here();
  s.args = {expr_of(a[1], who), expr_of(a[2], who)};
  s.number = static_number(a, n, 3, 0.0, who);
  s.callee = trace_scalar(a[0], who);
  Value r = new_var(RType::Real);
  s.outs = {var_of(r)};
  emit(std::move(s));
  return r;
}

Value P_bisect(Value *a, int n) {
  static const char who[] = "bisect";
  RStmt s{RKind::Bisect};
  s.loc = here();
  s.args = {expr_of(a[1], who), expr_of(a[2], who), expr_of(a[3], who)};
  s.number = static_number(a, n, 4, kBisectBreak, who);
  s.callee = trace_scalar(a[0], who);
  Value r = new_var(RType::Real);
  s.outs = {var_of(r)};
  emit(std::move(s));
  return r;
}

Value P_not_yet(Value *, int) {
  cannot_compile(here(), "this numerical primitive is not compiled yet");
}

// The integrator of argument i (or *ode-integration-method*) as the
// runtime's step type variable.
std::string method_of(Value *a, int n, int i, const char *who) {
  Value m =
      i < n && !a[i].is(Tag::Default) ? a[i] : intern("*ode-integration-method*").symbol()->global;
  const char *c = is_symbol(m) ? integrator_c_name(symbol_name(m)) : nullptr;
  if (!c) {
    std::string why = is_symbol(m) ? integrator_not_provided(symbol_name(m)) : "";
    if (!why.empty()) runtime_error(here(), std::string(who) + ": " + why);
    if (i < n) bad_range(a[i], i + 1, who);
    runtime_error(here(), std::string(who) + ": *ode-integration-method* is " + write_string(m) +
                              ", which names no integrator");
  }
  return c;
}

bool is_scalar_leaf(Value v) {
  return is_number(v) || is_dynamic_scalar(v);
}

// May a residual function hold this node? A symbol only if it is a
// run-time value, a call only if it is a linear solve.
bool run_time_node(ExprId id) {
  const ExprNode &n = expr_node(id);
  if (n.kind == ExprKind::Symbol) return g_var_of.count(n.sym) > 0;
  return n.kind != ExprKind::Call || is_solve_node(id);
}

// A system derivative's leaves as the outputs of its kernel, in the form
// sicm run's kernels take (codegen/kernel_form.hpp), so that both compute
// the same numbers.
std::vector<ExprId> system_outputs(const gcvec<Value> &leaves, const char *who) {
  for (Value leaf : leaves)
    if (leaf_expr(leaf) == kNoExpr) expr_of(leaf, who); // raises: not a number
  std::vector<ExprId> outputs = kernel_outputs(leaves, run_time_node);
  std::vector<bool> allowed = allowed_roots(outputs, run_time_node);
  for (size_t i = 0; i < outputs.size(); ++i)
    if (!allowed[i])
      cannot_compile(here(), std::string(who) + " needs a number here, not " + describe(leaves[i]));
  return outputs;
}

// Trace a system derivative on a state shaped like `state`; fills the
// statement's callee, time_first and rate_one. The derivative takes the
// form the interpreter's compiled derivatives take (kernel_outputs: evolve
// in `sicm run` compiles the same kernel, so both compute the same numbers).
void trace_system(Value sysder, Value state, RStmt &s, const char *who) {
  if (!is_state_shape(state)) wrong_type(state, 1, who);
  FunctionScope scope(procedure_name(sysder));
  gcvec<Value> x{input_like(state)};
  Value d = apply_traced(sysder, x); // as sicm run traces its kernels
  gcvec<Value> leaves;
  if (!derivative_leaves(d, state, leaves, is_scalar_leaf))
    cannot_compile(here(), std::string("the system derivative passed to ") + who + " returns " +
                               describe(d) + ", which is not shaped like the state " +
                               describe(state));
  std::vector<ExprId> outputs = system_outputs(leaves, who);
  current().outputs.insert(current().outputs.end(), outputs.begin(), outputs.end());
  s.callee = scope.id();
  size_t len;
  Value *items = container_items(state, &len);
  s.time_first = items && !container_items(items[0], &len);
  ExprId d0 = current().outputs[0];
  s.rate_one =
      expr_is_exact_one(d0) || (expr_kind(d0) == ExprKind::Flonum && expr_node(d0).d == 1.0);
}

// The taylor methods integrate with the Taylor coefficients of the
// solution, which residual_emit generates from the traced derivative: it
// must be one DAG of operations with recurrences, without statements (a
// test of a run-time value, a cell read) in its body.
void check_taylor(const RStmt &s, const char *who) {
  if (s.method != "sicm_ode_step_taylor" && s.method != "sicm_ode_step_taylor_extended") return;
  const char *method = s.method == "sicm_ode_step_taylor" ? "taylor" : "taylor-extended";
  const RFunction &f = g_prog->functions[s.callee];
  if (!f.body.empty())
    cannot_compile(s.loc, std::string(who) + ": " + method +
                              " needs a system derivative that is one expression of the state; "
                              "this one tests or reads run-time values; choose another "
                              "integrator");
  Trace t;
  for (int v : f.inputs)
    t.inputs.push_back(g_prog->vars[v].sym);
  t.outputs = f.outputs;
  std::string why_not;
  auto any_symbol = [](Symbol *) { return std::string("p[0]"); };
  if (emit_taylor_function(t, "check", &why_not, TaylorPrecision::Double, any_symbol).empty())
    cannot_compile(s.loc, std::string(who) + ": " + method +
                              " needs a compiled system derivative whose operations all have "
                              "Taylor recurrences; this one has " +
                              why_not);
}

// What the system derivative divides by, as a function of its own inputs
// (the same state's leaves), for the runtime to name where an integration
// fails (codegen/singular_factors.hpp).
void trace_singular_factors(Value state, RStmt &s) {
  std::vector<Symbol *> from;
  for (int v : g_prog->functions[s.callee].inputs)
    from.push_back(g_prog->vars[v].sym);
  std::vector<std::string> paths = state_leaf_paths(state, "state");
  std::unordered_map<Symbol *, std::string> names;
  for (size_t i = 0; i < from.size() && i < paths.size(); ++i)
    names[from[i]] = paths[i];
  SingularFactors factors = singular_factors(g_prog->functions[s.callee].outputs, [&](Symbol *sym) {
    auto it = names.find(sym);
    return it == names.end() ? std::string() : it->second;
  });
  if (factors.values.empty()) return;
  FunctionScope scope("singular_factors");
  input_like(state);
  std::vector<Symbol *> to;
  for (int v : current().inputs)
    to.push_back(g_prog->vars[v].sym);
  current().outputs = with_inputs(factors.values, from, to);
  s.probe = scope.id();
  s.probe_texts = std::move(factors.texts);
}

// For the implicit methods, the Jacobian (D sysder) traced as a function of
// the state too (its leaves: d f_i / d y_j at j * dim + i), as sicm run
// compiles it; left to finite differences when it cannot be traced.
void trace_jacobian(Value sysder, Value state, RStmt &s) {
  if (s.method != "sicm_ode_step_msbdf" && s.method != "sicm_ode_step_cvode_bdf") return;
  Symbol *d = intern("D").symbol();
  if (!d->bound) return;
  size_t nfunctions = g_prog->functions.size(), nvars = g_prog->vars.size();
  try {
    FunctionScope scope("jacobian");
    Value dsys = apply_procedure(d->global, &sysder, 1);
    gcvec<Value> x{input_like(state)};
    Value j = apply_traced(dsys, x);
    gcvec<Value> leaves;
    state_leaves(j, leaves);
    size_t n = current().inputs.size();
    if (leaves.size() != n * n) return;
    std::vector<ExprId> outputs = system_outputs(leaves, "jacobian");
    current().outputs.insert(current().outputs.end(), outputs.begin(), outputs.end());
    s.jacobian = scope.id();
  } catch (const Error &) {
    for (size_t v = nvars; v < g_prog->vars.size(); ++v)
      g_var_of.erase(g_prog->vars[v].sym);
    g_prog->functions.resize(nfunctions);
    g_prog->vars.resize(nvars);
    s.jacobian = -1;
  }
}

Value state_result(Value state, RStmt &s) {
  gcvec<Value> leaves;
  state_leaves(state, leaves);
  for (Value &leaf : leaves) {
    leaf = new_var(RType::Real);
    s.outs.push_back(var_of(leaf));
  }
  return state_from_leaves(state, leaves);
}

void state_args(Value state, RStmt &s, const char *who) {
  gcvec<Value> leaves;
  state_leaves(state, leaves);
  for (Value leaf : leaves)
    s.args.push_back(expr_of(leaf, who));
}

Lambda g_advancer_lambda, g_evolver_lambda;

Value make_named(NativeFn fn, Value sysder, Lambda *lambda) {
  Value p = make_native_procedure(fn, 0, sysder, Value::nil());
  static_cast<NativeProc *>(p.as<Opaque>()->obj)->print_as.lambda = lambda;
  return p;
}

Value sysder_of(Value *a, int n, const char *who) {
  if (n < 1 || !is_procedure(a[0])) wrong_type(n < 1 ? Value::nil() : a[0], 1, who);
  return apply_procedure(a[0], a + 1, n - 1);
}

Value advance(NativeProc *self, Value *a, int n) {
  static const char who[] = "state-advancer";
  if (n < 2 || n > 4) native_arity_error(self, n, 2);
  RStmt s{RKind::Advance};
  s.loc = here();
  s.number = static_number(a, n, 2, kAdvancerTolerance, who);
  s.method = method_of(a, n, 3, who);
  state_args(a[0], s, who);
  s.args.push_back(expr_of(a[1], who));
  trace_system(self->a, a[0], s, who);
  check_taylor(s, who);
  trace_singular_factors(a[0], s);
  trace_jacobian(self->a, a[0], s);
  Value r = state_result(a[0], s);
  emit(std::move(s));
  return r;
}

Value P_state_advancer(Value *a, int n) {
  return make_named(retrying_native<advance>, sysder_of(a, n, "state-advancer"),
                    &g_advancer_lambda);
}

Value run_evolve(NativeProc *self, Value *a, int n) {
  static const char who[] = "evolve";
  if (n < 4 || n > 6) native_arity_error(self, n, 4);
  RStmt s{RKind::Evolve};
  s.loc = here();
  s.number = static_number(a, n, 4, kAdvancerTolerance, who);
  s.method = method_of(a, n, 5, who);
  state_args(a[0], s, who);
  s.args.push_back(expr_of(a[2], who));
  s.args.push_back(expr_of(a[3], who));
  trace_system(self->a, a[0], s, who);
  check_taylor(s, who);
  trace_singular_factors(a[0], s);
  trace_jacobian(self->a, a[0], s);
  Value monitor = a[1];
  if (!is_procedure(monitor)) wrong_type(monitor, 2, who);
  {
    FunctionScope scope(procedure_name(monitor));
    Value x = input_like(a[0]);
    apply_procedure(monitor, &x, 1);
    s.monitor = scope.id();
  }
  Value r = state_result(a[0], s);
  emit(std::move(s));
  return r;
}

Value P_evolve(Value *a, int n) {
  return make_named(retrying_native<run_evolve>, sysder_of(a, n, "evolve"), &g_evolver_lambda);
}

// ---- plots ------------------------------------------------------------------------------

struct BuildPlot {
  int id;
  char *name; // GC memory
};

void write_plot(std::string &out, const void *obj, bool) {
  out += "#[graphics-device ";
  out += static_cast<const BuildPlot *>(obj)->name;
  out += "]";
}

const OpaqueKind kBuildPlotKind = {"graphics-device", write_plot, nullptr};

BuildPlot *arg_plot(Value *a, int i, const char *who) {
  if (!a[i].is(Tag::Opaque) || a[i].as<Opaque>()->kind != &kBuildPlotKind)
    wrong_type(a[i], i + 1, who);
  return static_cast<BuildPlot *>(a[i].as<Opaque>()->obj);
}

Value P_frame(Value *a, int n) {
  static const char who[] = "frame";
  RStmt s{RKind::Frame};
  s.loc = here();
  double r[4];
  for (int i = 0; i < 4; ++i) {
    if (is_dynamic_scalar(a[i]))
      cannot_compile(here(), "a frame's bounds must be known at compile time");
    if (!is_number(a[i])) wrong_type(a[i], i + 1, who);
    r[i] = to_double(a[i]);
    s.args.push_back(expr_flonum(r[i]));
  }
  if (!(r[1] > r[0])) bad_range(a[1], 2, who);
  if (!(r[3] > r[2])) bad_range(a[3], 4, who);
  s.plot = ++g_prog->plots;
  s.title = n > 4 ? std::string(arg_string(a, 4, who)) : "";
  s.text = plot_file_name(s.title, s.plot);
  for (int i = 5; i < n; ++i) // the axis labels
    s.axis_labels.emplace_back(arg_string(a, i, who));
  BuildPlot *p = gc_new<BuildPlot>(BuildPlot{s.plot, gc_strdup(s.text)});
  emit(std::move(s));
  return Value::object(Tag::Opaque, gc_new<Opaque>(Opaque{&kBuildPlotKind, p}));
}

Value P_plot_point(Value *a, int) {
  RStmt s{RKind::PlotPoint};
  s.plot = arg_plot(a, 0, "plot-point")->id;
  s.args = {expr_of(a[1], "plot-point"), expr_of(a[2], "plot-point")};
  emit(std::move(s));
  return Value::unspecified();
}

Value P_plot_line(Value *a, int) {
  RStmt s{RKind::PlotLine};
  s.plot = arg_plot(a, 0, "plot-line")->id;
  for (int i = 1; i <= 4; ++i)
    s.args.push_back(expr_of(a[i], "plot-line"));
  emit(std::move(s));
  return Value::unspecified();
}

Value P_graphics_close(Value *a, int) {
  RStmt s{RKind::Close};
  s.plot = arg_plot(a, 0, "graphics-close")->id;
  emit(std::move(s));
  return Value::unspecified();
}

Value P_graphics_clear(Value *a, int) {
  arg_plot(a, 0, "graphics-clear");
  return Value::unspecified();
}

// ---- branches on run-time values --------------------------------------------------------

// Only a truth value can be false: a run-time number is true, as every number is.
bool hook_dynamic_test(Value test) {
  return is_dynamic_boolean(test);
}

// The value that is `a` when test holds at run time and `b` otherwise.
bool is_bottom(Value v);

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
    RType ta = scalar_type(a), tb = scalar_type(b);
    if (ta != tb)
      cannot_compile(here(), "the alternatives of a test on a value known only at run time give " +
                                 describe(a) + " and " + describe(b) +
                                 ", numbers of different kinds (exact and inexact)");
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
  RtList *ra = as_rtlist(a), *rb = as_rtlist(b);
  if (ra && rb && ra->list == rb->list && ra->reversed == rb->reversed)
    return make_rtlist(ra->list, ra->reversed, false, select_values(test, ra->start, rb->start),
                       select_values(test, ra->end, rb->end));
  cannot_compile(here(), "the alternatives of a test on a value known only at run time give " +
                             describe(a) + " and " + describe(b) +
                             ", which cannot be chosen between at run time");
}

// Globals assigned while an alternative is evaluated: their values before
// and after, so the other alternative starts from the same state and both
// outcomes can be merged.
struct Assignment {
  Value *place; // a global's value or a frame slot
  Value before, after;
  uint32_t serial = 0; // the frame's serial (0 for a global)
};

std::vector<gcvec<Assignment> *> g_undo; // logs hold Values: collected memory
// g_frame_serial when each log began: a local variable of a frame made
// later belongs to the alternative (or loop body) itself and is not logged.
std::vector<uint32_t> g_undo_serials;

// Add a to the innermost log, if its variable is older than the log.
void log_assignment(const Assignment &a) {
  if (!g_undo.empty() && a.serial <= g_undo_serials.back()) g_undo.back()->push_back(a);
}

// Evaluate one alternative under a run-time test.
Value speculate(const std::function<Value()> &alternative) {
  if (g_branch_depth >= kMaxBranchDepth)
    cannot_compile(here(), "a loop or recursion whose end depends on a value known only at run "
                           "time");
  if (++g_branch_evaluations > kMaxBranchEvaluations)
    cannot_compile(here(), "more than " + std::to_string(kMaxBranchEvaluations) +
                               " alternatives under tests on run-time values: the program "
                               "unfolds too much (a loop whose arguments change shape, such as "
                               "a list that grows, cannot become a C loop and is unfolded)");
  ++g_branch_depth;
  try {
    Value v = alternative();
    --g_branch_depth;
    return v;
  } catch (...) {
    --g_branch_depth;
    throw;
  }
}

// Evaluate one alternative into its own block of statements, then undo
// its assignments to globals (recorded in *log).
Value alternative(std::vector<RStmt> &block, gcvec<Assignment> &log,
                  const std::function<Value()> &eval_it) {
  g_blocks.push_back(&block);
  g_undo.push_back(&log);
  g_undo_serials.push_back(g_frame_serial);
  auto restore = [&] {
    g_blocks.pop_back();
    g_undo.pop_back();
    g_undo_serials.pop_back();
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

// Does the block call a function or add to a list (after which cells and
// lists are read again)?
bool block_calls(const std::vector<RStmt> &block) {
  for (const RStmt &s : block)
    if (s.callee >= 0 || s.monitor >= 0 || s.kind == RKind::ListPush || block_calls(s.then_body) ||
        block_calls(s.else_body))
      return true;
  return false;
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
  if (!g_undo.empty()) { // an enclosing alternative undoes what these did, too
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

Value push_onto_list(Value *place, const std::string &name, Value element, SrcLoc loc,
                     bool may_create, Frame *frame, bool in_loop);

bool grows_in_loop(Frame *frame);

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
    if (scalar_type(v) == RType::Real) g_prog->cells[cell].type = RType::Real;
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
    g_prog->cells.push_back(RCell{place, name, scalar_type(*place)});
    g_cell_initialized.push_back(false);
    if (frame) g_cell_frames.push_back(frame);
    throw Retrace{};
  }
  RCell &c = g_prog->cells[cell];
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

Value hook_set_global(Symbol *s, Value v, SrcLoc loc) {
  return assign(&s->global, "the global variable " + s->name, v, loc, g_open.size() > 1,
                g_open.size() == 2, nullptr);
}

Value hook_set_local(Frame *f, uint32_t index, Value v, SrcLoc loc) {
  // Frames made before the innermost traced procedure began belong to its
  // callers: state kept across run-time calls.
  bool outer = g_open.size() > 1 && f->serial <= g_function_serials.back();
  bool may_create = g_open.size() == 2;
  return assign(&f->slots[index], "a local variable", v, loc, outer, may_create, f);
}

// ---- loops: named procedures called again with run-time arguments ------------------------
//
// A call of a named procedure with a run-time number among its arguments is
// evaluated as a loop candidate: its parameters that get run-time values
// become loop variables, and a call of the same procedure (closure) while its
// body is being evaluated records "continue with these values" and gives
// Bottom, a value that never reaches a result: a test on a run-time value
// whose alternative is Bottom selects the other one. If the body never calls
// itself, its statements are spliced in place (it was an ordinary call);
// else they become a C loop whose result is the value the body gives on the
// paths that do not call it again. A parameter that gets a different known
// number in the recursive call becomes a loop variable too (the body is
// evaluated again); anything else (a list that shrinks, a result used by the
// caller as in (* n (fact (- n 1))), a structure as argument) abandons the
// loop, and the call is evaluated as it always is.

struct LoopRetry {}; // evaluate the loop's body again with more loop variables
struct LoopAbort {}; // not a loop: evaluate the call as usual

void throw_not_a_loop() {
  throw LoopAbort{};
}

void write_bottom(std::string &out, const void *, bool) {
  out += "#[the value of a recursive call]";
}

const OpaqueKind kBottomKind = {"run-time-loop-continuation", write_bottom, nullptr};
Value g_bottom;

bool is_bottom(Value v) {
  return v.is(Tag::Opaque) && v.as<Opaque>()->kind == &kBottomKind;
}

// The scalar leaves of a loop's result (a number or truth value, or a proper
// list, structure or vector of them); false if it has others.
bool result_leaves(Value v, gcvec<Value> &out) {
  if (is_bottom(v)) return false;
  if (RtList *r = as_rtlist(v)) { // a run-time list: its ends
    out.push_back(r->start);
    out.push_back(r->end);
    return true;
  }
  if (is_scalar(v)) {
    out.push_back(v);
    return true;
  }
  if (!contains_dynamic(v) && !is_pair(v) && !container_items_of(v)) return true; // kept as is
  if (is_pair(v)) return result_leaves(car(v), out) && result_leaves(cdr(v), out);
  size_t len;
  Value *items = container_items(v, &len);
  if (!items) return false;
  for (size_t i = 0; i < len; ++i)
    if (!result_leaves(items[i], out)) return false;
  return true;
}

// A value shaped like `shape` (as result_leaves walks it) with new leaves.
Value result_like(Value shape, const Value *&leaves) {
  if (is_scalar(shape)) return *leaves++;
  if (RtList *r = as_rtlist(shape)) {
    Value start = *leaves++;
    return make_rtlist(r->list, r->reversed, false, start, *leaves++);
  }
  if (!contains_dynamic(shape) && !is_pair(shape) && !container_items_of(shape)) return shape;
  if (is_pair(shape)) {
    Value a = result_like(car(shape), leaves);
    return cons(a, result_like(cdr(shape), leaves));
  }
  return state_like(shape, leaves, result_like);
}

// A parameter of a loop: known (the first call's argument, which every
// call must repeat) or a loop variable: a number, a truth value, or a
// list, structure or vector of them, one C variable per leaf.
struct LoopParam {
  bool variable = false;
  Value shape;              // the first call's argument
  std::vector<RType> types; // of the leaves
  std::vector<int> vars;    // the leaves' variables in the current attempt
};

struct ActiveLoop {
  Closure *closure;
  size_t depth = 0;        // g_open.size(): the function the loop is in
  uint32_t serial = 0;     // g_frame_serial when the current attempt began
  bool watching = false;   // evaluated as an ordinary call until it calls itself
  gcvec<LoopParam> params; // holds Values: collected memory
  bool continued = false;
  bool from_known = false; // every argument of the first call was known (see StaticWatch)
};

struct BecomeLoop { // a watched call called itself: evaluate it as a loop
  Closure *closure;
};
std::vector<ActiveLoop *> g_loops; // loops whose bodies are being evaluated, innermost last

// Do a and b have the same shape as loop values: both scalars, or lists,
// structures or vectors of the same lengths with the same shapes inside?
bool same_shape(Value a, Value b) {
  if (is_scalar(a) || is_scalar(b)) return is_scalar(a) && is_scalar(b);
  if (as_rtlist(a) || as_rtlist(b))
    return as_rtlist(a) && as_rtlist(b) && as_rtlist(a)->list == as_rtlist(b)->list &&
           as_rtlist(a)->reversed == as_rtlist(b)->reversed;
  if (!is_pair(a) && !container_items_of(a) && !contains_dynamic(a)) return eqv(a, b);
  if (is_pair(a) || is_pair(b))
    return is_pair(a) && is_pair(b) && same_shape(car(a), car(b)) && same_shape(cdr(a), cdr(b));
  size_t la = 0, lb = 0;
  Value *x = container_items(a, &la), *y = container_items(b, &lb);
  if (!x || !y || la != lb || a.tag != b.tag) return false;
  if (is_structure(a) && as_structure(a)->up != as_structure(b)->up) return false;
  for (size_t i = 0; i < la; ++i)
    if (!same_shape(x[i], y[i])) return false;
  return true;
}

// Make parameter p a loop variable shaped like v (a retry follows).
void make_variable(LoopParam &p, Value v) {
  gcvec<Value> leaves;
  if (!result_leaves(v, leaves)) throw LoopAbort{};
  p.variable = true;
  p.types.clear();
  for (Value leaf : leaves)
    p.types.push_back(scalar_type(leaf));
}

// A known value a loop started from known values may turn into a loop
// variable: a truth value, an inexact number, or an exact integer that a
// double holds exactly (an exact fraction prints differently from a double).
bool is_loop_number(Value v) {
  if (v.is(Tag::Flonum) || v.is(Tag::Bool) || is_dynamic_scalar(v)) return true;
  return v.is(Tag::Fixnum) && v.i <= (int64_t(1) << 53) && v.i >= -(int64_t(1) << 53);
}

Value record_continue(ActiveLoop &loop, Value *a, long n) {
  RStmt s{RKind::Continue};
  for (long i = 0; i < n; ++i) {
    LoopParam &p = loop.params[i];
    if (!p.variable) {
      if (eqv(a[i], p.shape)) continue;
      gcvec<Value> leaves;
      if (!result_leaves(a[i], leaves) || !same_shape(a[i], p.shape))
        throw LoopAbort{}; // a list that shrinks, ...
      if (loop.from_known)
        for (Value leaf : leaves)
          if (!is_loop_number(leaf)) throw LoopAbort{};
      make_variable(p, a[i]); // known numbers that change: loop variables
      throw LoopRetry{};
    }
    gcvec<Value> leaves;
    if (!same_shape(a[i], p.shape) || !result_leaves(a[i], leaves)) throw LoopAbort{};
    for (size_t k = 0; k < leaves.size(); ++k) {
      RType t = scalar_type(leaves[k]);
      if (t != p.types[k]) {
        if (t == RType::Boolean || p.types[k] == RType::Boolean) throw LoopAbort{};
        p.types[k] = RType::Real; // counts that become reals
        throw LoopRetry{};
      }
      s.outs.push_back(p.vars[k]);
      s.args.push_back(expr_of(leaves[k], "loop"));
    }
  }
  emit(std::move(s));
  loop.continued = true;
  return g_bottom;
}

// Restores the builder's stacks and the program's size when a loop attempt
// ends, by return or by exception.
class LoopAttempt {
public:
  LoopAttempt(ActiveLoop *loop, std::vector<RStmt> *block)
      : nfunctions_(g_prog->functions.size()), nvars_(g_prog->vars.size()), nloops_(g_loops.size()),
        nblocks_(g_blocks.size()), nundo_(g_undo.size()) {
    g_loops.push_back(loop);
    g_blocks.push_back(block);
    g_undo.push_back(&log_);
    g_undo_serials.push_back(g_frame_serial);
  }
  ~LoopAttempt() {
    g_loops.resize(nloops_);
    g_blocks.resize(nblocks_);
    g_undo.resize(nundo_);
    g_undo_serials.resize(nundo_);
  }
  // Forget everything the attempt made.
  void roll_back() {
    for (auto a = log_.rbegin(); a != log_.rend(); ++a)
      *a->place = a->before;
    for (size_t v = nvars_; v < g_prog->vars.size(); ++v)
      g_var_of.erase(g_prog->vars[v].sym);
    g_prog->functions.resize(nfunctions_);
    g_prog->vars.resize(nvars_);
  }
  const gcvec<Assignment> &log() const { return log_; }

private:
  size_t nfunctions_, nvars_, nloops_, nblocks_, nundo_;
  gcvec<Assignment> log_;
};

bool evaluate_as_loop(Value f, Value *slots, long n, Value *out, bool from_known);
bool watch_known_call(Value f, Value *slots, long n, Value *out);
bool count_known_call(Closure *c);

bool hook_call_closure(Value f, Value *slots, long n, Value *out) {
  Closure *c = f.as<Closure>();
  for (auto l = g_loops.rbegin(); l != g_loops.rend(); ++l)
    if ((*l)->closure == c) {
      if ((*l)->watching) throw BecomeLoop{c};
      *out = record_continue(**l, slots, n);
      return true;
    }
  if (!c->lambda->name) return false;
  bool any = false;
  for (long i = 0; i < n; ++i)
    any = any || contains_dynamic(slots[i]) || is_dynamic_boolean(slots[i]);
  if (!any) {
    if (count_known_call(c)) return false; // an iteration of a watched call
    return watch_known_call(f, slots, n, out);
  }

  // First as an ordinary call, watched: most calls never call themselves.
  {
    std::vector<RStmt> body;
    Value v;
    gcvec<Assignment> assigned;
    bool recursive = false;
    {
      ActiveLoop watch;
      watch.closure = c;
      watch.watching = true;
      LoopAttempt attempt(&watch, &body);
      gcvec<Value> args(slots, slots + n);
      try {
        v = apply_procedure(f, args.data(), static_cast<int>(n));
        assigned = attempt.log();
      } catch (const BecomeLoop &b) {
        attempt.roll_back();
        if (b.closure != c) throw;
        recursive = true;
      }
    }
    if (!recursive) {
      if (!g_undo.empty()) // an enclosing alternative undoes these assignments too
        for (const Assignment &a : assigned)
          log_assignment(a);
      for (RStmt &x : body)
        current_block().push_back(std::move(x));
      *out = v;
      return true;
    }
  }

  return evaluate_as_loop(f, slots, n, out, false);
}

// The call of closure f with arguments slots as a loop (see above);
// from_known: all of them are known (see StaticWatch). False if it is not one.
bool evaluate_as_loop(Value f, Value *slots, long n, Value *out, bool from_known) {
  Closure *c = f.as<Closure>();
  ActiveLoop loop;
  loop.closure = c;
  loop.from_known = from_known;
  for (long i = 0; i < n; ++i) {
    LoopParam p;
    p.shape = slots[i];
    if (contains_dynamic(slots[i]) || is_dynamic_boolean(slots[i])) {
      gcvec<Value> leaves;
      if (!result_leaves(slots[i], leaves)) return false; // a procedure, ...: not a loop
      make_variable(p, slots[i]);
    }
    loop.params.push_back(std::move(p));
  }
  for (;;) {
    std::vector<RStmt> body;
    Value v;
    bool retry = false;
    gcvec<Value> saved_lists;
    for (Value *place : list_cell_places())
      saved_lists.push_back(*place);
    gcvec<Assignment> assigned;
    {
      LoopAttempt attempt(&loop, &body);
      loop.continued = false;
      loop.depth = g_open.size();
      loop.serial = g_frame_serial;
      read_list_cells(); // their lengths as each iteration begins
      gcvec<Value> args(slots, slots + n);
      for (long i = 0; i < n; ++i) {
        LoopParam &p = loop.params[i];
        if (!p.variable) continue;
        gcvec<Value> leaves;
        p.vars.clear();
        for (RType t : p.types) {
          leaves.push_back(new_var(t));
          p.vars.push_back(var_of(leaves.back()));
        }
        const Value *lp = leaves.data();
        args[i] = result_like(p.shape, lp);
      }
      try {
        v = apply_procedure(f, args.data(), static_cast<int>(n));
        gcvec<Value> leaves;
        if (loop.continued && !result_leaves(v, leaves)) throw LoopAbort{};
        for (const Assignment &a : attempt.log())
          if (loop.continued && cell_of(a.place) < 0 &&
              !(list_cell_of(a.place) >= 0 && is_whole_list(a.after)))
            throw LoopAbort{};
        assigned = attempt.log();
      } catch (const LoopRetry &) {
        attempt.roll_back();
        retry = true;
      } catch (const LoopAbort &) {
        attempt.roll_back();
        return false;
      } catch (const Error &) {
        attempt.roll_back();
        return false; // evaluated again as usual: the error, if real, comes again
      }
    } // the stacks are the caller's again
    for (size_t i = 0; i < saved_lists.size(); ++i)
      *list_cell_places()[i] = saved_lists[i]; // read again after the loop if it added to them
    if (retry) {
      init_list_cells(); // lists the body conses onto start before the loop
      continue;
    }
    if (!g_undo.empty()) // an enclosing alternative undoes these assignments too
      for (const Assignment &a : assigned)
        log_assignment(a);
    bool calls = block_calls(body);
    RStmt s{loop.continued ? RKind::Loop : RKind::If};
    for (const LoopParam &p : loop.params) {
      if (!p.variable) continue;
      gcvec<Value> inits;
      result_leaves(p.shape, inits);
      for (size_t k = 0; k < inits.size(); ++k) {
        s.outs.push_back(p.vars[k]);
        s.args.push_back(expr_of(inits[k], "loop"));
      }
    }
    if (!loop.continued) {
      // An ordinary call: its variables get their values, its statements
      // follow in place.
      for (size_t i = 0; i < s.outs.size(); ++i) {
        RStmt l{RKind::Let};
        l.var = s.outs[i];
        l.args = {s.args[i]};
        emit(std::move(l));
      }
      for (RStmt &x : body)
        current_block().push_back(std::move(x));
      if (calls) read_cells();
      *out = v;
      return true;
    }
    gcvec<Value> leaves, results;
    result_leaves(v, leaves);
    RStmt brk{RKind::Break};
    for (Value leaf : leaves) {
      results.push_back(new_var(scalar_type(leaf)));
      brk.results.push_back(var_of(results.back()));
      brk.args.push_back(expr_of(leaf, "loop"));
    }
    s.results = brk.results;
    body.push_back(std::move(brk));
    s.then_body = std::move(body);
    current_block().push_back(std::move(s));
    if (calls) read_cells();
    const Value *p = results.data();
    *out = result_like(v, p);
    return true;
  }
}

// ---- lists whose length is known only at run time ----------------------------------------
//
// A procedure run at run time (a monitor) that conses onto a variable it
// keeps from one call to the next, (set! l (cons x l)), makes the variable a
// list cell: the list becomes the runtime's array listN (sicm/program.h), to
// which each run-time call adds its element; like a cell, the variable is
// read again (its length) where a traced procedure begins and after every
// call that may have added to it. Every element must have one shape: a number
// or truth value, or a pair, structure or vector of them (static parts, a
// symbol say, are kept in the shape), so that an element is a fixed number of
// doubles. A list value is an RtList: a range of the array read in one
// direction, so that car, cdr, null?, length, list-ref and reverse are
// arithmetic on its ends; map and for-each become C loops over it, apply of
// min, max, + or * a runtime fold, and a named let whose arguments are such
// lists (walking them with null?, car and cdr) a C loop as for numbers (the
// ends are its variables: see result_leaves). Anything else done with such a
// list (print it, append to it, keep it in a list of lists) is a compile error.

struct ListCell {
  Value *place; // the variable (a global's value or a frame slot)
  std::string name;
  int list = -1;            // the list the variable holds now
  bool needs_init = true;   // the next push starts a new list from the variable's value
  std::vector<RType> types; // of the element whose push asked for a new list
};
std::vector<ListCell> g_list_cells;
gcvec<Value> g_list_cell_elements; // per cell: the shape of the element that asked for a new list
gcvec<Value> g_list_shapes;        // per list: its elements' shape
std::vector<std::vector<RType>> g_list_types; // per list: its elements' leaves' kinds

int list_cell_of(const Value *place) {
  for (size_t i = 0; i < g_list_cells.size(); ++i)
    if (g_list_cells[i].place == place) return static_cast<int>(i);
  return -1;
}

std::vector<Value *> list_cell_places() {
  std::vector<Value *> places;
  for (const ListCell &c : g_list_cells)
    places.push_back(c.place);
  return places;
}

bool is_whole_list(Value v) {
  RtList *r = as_rtlist(v);
  return r && r->whole;
}

bool contains_rtlist(Value v) {
  if (as_rtlist(v)) return true;
  if (is_pair(v)) return contains_rtlist(car(v)) || contains_rtlist(cdr(v));
  size_t len;
  Value *items = container_items(v, &len);
  for (size_t i = 0; items && i < len; ++i)
    if (contains_rtlist(items[i])) return true;
  return false;
}

// The leaves of a list element, or false if it cannot be one.
bool element_leaves(Value v, gcvec<Value> &out) {
  return !contains_rtlist(v) && !is_bottom(v) && result_leaves(v, out);
}

// The shape of an element (which may mention variables a retrace forgets):
// its leaves replaced by 0.
Value element_shape(Value element) {
  gcvec<Value> leaves;
  element_leaves(element, leaves);
  for (Value &leaf : leaves)
    leaf = Value::fixnum(0);
  const Value *p = leaves.data();
  return result_like(element, p);
}

std::vector<RType> leaf_types(const gcvec<Value> &leaves) {
  std::vector<RType> types;
  for (Value leaf : leaves)
    types.push_back(scalar_type(leaf));
  return types;
}

// A new empty list for elements shaped like `shape`.
int new_list(Value shape, const std::vector<RType> &types, const std::string &name) {
  int id = static_cast<int>(g_prog->lists.size());
  g_prog->lists.push_back(RList{static_cast<int>(types.size()), name});
  g_list_shapes.push_back(element_shape(shape));
  g_list_types.push_back(types);
  RStmt s{RKind::ListNew};
  s.list = id;
  emit(std::move(s));
  return id;
}

void push_leaves(int list, const gcvec<Value> &leaves) {
  RStmt s{RKind::ListPush};
  s.list = list;
  for (Value leaf : leaves)
    s.args.push_back(expr_of(leaf, "cons"));
  emit(std::move(s));
}

Value count_plus(Value n, long k) {
  return k == 0 ? n : g_add(n, Value::fixnum(k));
}

// Is a variable of `frame` (null: a global) kept from one iteration to the
// next of the loop being evaluated for run time, in the same function?
bool grows_in_loop(Frame *frame) {
  if (g_loops.empty()) return false;
  const ActiveLoop *loop = g_loops.back();
  return !loop->watching && loop->depth == g_open.size() &&
         (!frame || frame->serial <= loop->serial);
}

// Evaluate again what added to a list that must first be started: the loop
// that conses onto it, or the numerical primitive whose procedure does.
[[noreturn]] void retry_for_list(bool in_loop) {
  if (in_loop) throw LoopRetry{};
  throw Retrace{};
}

// (set! l (cons element l)) in a procedure run at run time, or in a loop left
// for run time (in_loop): add the element to the run-time list l holds, or
// (l holding a list known at compile time) start a new one, tracing the
// primitive (evaluating the loop) again.
Value push_onto_list(Value *place, const std::string &name, Value element, SrcLoc loc,
                     bool may_create, Frame *frame, bool in_loop) {
  int cell = list_cell_of(place);
  RtList *r = as_rtlist(*place);
  gcvec<Value> leaves;
  if (!element_leaves(element, leaves))
    cannot_compile(loc, "set! of " + name + " to a list of " + describe(element) +
                            " inside a procedure that runs at run time (the elements of a list "
                            "of run-time length must be numbers, or pairs or structures of them)");
  if (cell >= 0 && r && r->whole && r->list == g_list_cells[cell].list) {
    int list = r->list;
    if (!same_shape(element, g_list_shapes[list]))
      cannot_compile(loc, "set! of " + name + " to a list whose elements have different shapes, " +
                              describe(element) + " and " + describe(g_list_shapes[list]));
    std::vector<RType> &types = g_list_types[list];
    for (size_t k = 0; k < leaves.size(); ++k) {
      RType t = scalar_type(leaves[k]);
      if (t == types[k]) continue;
      if (t == RType::Boolean || types[k] == RType::Boolean)
        cannot_compile(loc, "set! of " + name + " to a list of truth values and numbers");
      if (types[k] == RType::Integer) {
        types[k] = RType::Real; // counts widen to reals: trace again with real reads
        retry_for_list(in_loop);
      }
    }
    push_leaves(list, leaves);
    return make_rtlist(list, false, true, r->start, count_plus(r->end, 1));
  }
  if (r || list_length(*place) < 0 || contains_dynamic(*place))
    cannot_compile(loc, "set! of " + name + " to (cons " + describe(element) + " " +
                            describe(*place) +
                            ") inside a procedure that runs at run time: a run-time list can "
                            "only grow from the list the variable held before the primitive ran");
  for (Value x = *place; is_pair(x); x = cdr(x))
    if (!same_shape(car(x), element))
      cannot_compile(loc, "set! of " + name + " to a list whose elements have different shapes, " +
                              describe(element) + " and " + describe(car(x)));
  if (!may_create)
    cannot_compile(loc,
                   "set! of " + name + " inside a procedure run by another run-time procedure");
  if (cell < 0) {
    g_list_cells.push_back(ListCell{place, name, -1, true, {}});
    g_list_cell_elements.push_back(element);
    if (frame) g_cell_frames.push_back(frame);
    cell = static_cast<int>(g_list_cells.size()) - 1;
  }
  g_list_cells[cell].needs_init = true;
  g_list_cells[cell].types = leaf_types(leaves);
  g_list_cell_elements[cell] = element_shape(element);
  retry_for_list(in_loop);
}

// Start the lists that pushes asked for, from the values their variables
// hold (before the primitive that is traced again).
void init_list_cells() {
  for (size_t i = 0; i < g_list_cells.size(); ++i) {
    ListCell &c = g_list_cells[i];
    if (!c.needs_init) continue;
    c.needs_init = false;
    Value element = g_list_cell_elements[i];
    const std::vector<RType> &types = c.types;
    c.list = new_list(element, types, c.name);
    gcvec<Value> items = list_to_vector(*c.place);
    for (size_t k = items.size(); k-- > 0;) {
      gcvec<Value> xs;
      element_leaves(items[k], xs);
      if (leaf_types(xs) != types)
        cannot_compile(here(), "the list " + c.name + " holds " + describe(items[k]) +
                                   " and gets " + describe(element) +
                                   ", numbers of different kinds (exact and inexact)");
      push_leaves(c.list, xs);
    }
    *c.place = make_rtlist(c.list, false, true, Value::fixnum(0),
                           Value::fixnum(static_cast<long>(items.size())));
  }
}

// A list cell's variable holding its whole list gets the list's length now.
void read_list_cells() {
  for (ListCell &c : g_list_cells) {
    RtList *r = as_rtlist(*c.place);
    if (!r || !r->whole || r->list != c.list) continue;
    RStmt s{RKind::Let};
    s.compute = RCompute::ListLength;
    s.list = c.list;
    Value n = new_var(RType::Integer);
    s.var = var_of(n);
    current_block().push_back(std::move(s));
    *c.place = make_rtlist(c.list, false, true, Value::fixnum(0), n);
  }
}

// The position in the array of element k (a count) of r.
Value list_position(const RtList *r, Value k) {
  if (r->reversed) return g_add(r->start, k);
  return g_sub(count_plus(r->end, -1), k);
}

// Element k of r, read at run time (who: for the error if there is none).
Value list_element(const RtList *r, Value k, const char *who) {
  Value position = list_position(r, k);
  const std::vector<RType> &types = g_list_types[r->list];
  gcvec<Value> leaves;
  for (size_t i = 0; i < types.size(); ++i) {
    RStmt s{RKind::Let};
    s.compute = RCompute::ListRef;
    s.list = r->list;
    s.leaf = static_cast<int>(i);
    s.text = who;
    s.args = {expr_of(position, who), expr_of(r->start, who), expr_of(r->end, who)};
    Value v = new_var(types[i]);
    s.var = var_of(v);
    emit(std::move(s));
    leaves.push_back(v);
  }
  const Value *p = leaves.data();
  return result_like(g_list_shapes[r->list], p);
}

// r without its first k elements.
Value list_tail(const RtList *r, Value k) {
  if (r->reversed) return make_rtlist(r->list, true, false, g_add(r->start, k), r->end);
  return make_rtlist(r->list, false, false, r->start, g_sub(r->end, k));
}

Value list_count(const RtList *r) {
  return g_sub(r->end, r->start);
}

Value list_is_empty(const RtList *r) {
  if (!is_dynamic_scalar(r->start) && !is_dynamic_scalar(r->end))
    return Value::boolean(to_double(r->start) == to_double(r->end));
  return let(RCompute::Equal, {expr_of(r->start, "null?"), expr_of(r->end, "null?")},
             RType::Boolean);
}

// A count argument: an exact integer or a run-time number.
Value count_arg(Value *a, int i, const char *who) {
  if (is_dynamic_scalar(a[i])) return a[i];
  if (!a[i].is(Tag::Fixnum) || a[i].i < 0) wrong_type(a[i], i + 1, who);
  return a[i];
}

// A list that ends in a run-time list after some pairs known at compile time.
bool has_rtlist_tail(Value v) {
  while (is_pair(v))
    v = cdr(v);
  return as_rtlist(v) != nullptr;
}

[[noreturn]] void refuse_list(Value v, const char *who) {
  cannot_compile(here(), std::string(who) + " of " + describe(v) +
                             ", a list whose length is known only at run time");
}

Value P_list_car(Value *a, int n) {
  if (RtList *r = as_rtlist(a[0])) return list_element(r, Value::fixnum(0), "car");
  return call_original("car", a, n);
}

Value P_list_cdr(Value *a, int n) {
  if (RtList *r = as_rtlist(a[0])) return list_tail(r, Value::fixnum(1));
  return call_original("cdr", a, n);
}

Value P_list_null(Value *a, int n) {
  if (RtList *r = as_rtlist(a[0])) return list_is_empty(r);
  return call_original("null?", a, n);
}

Value P_list_pair(Value *a, int n) {
  if (RtList *r = as_rtlist(a[0])) {
    Value e = list_is_empty(r);
    if (e.is(Tag::Bool)) return Value::boolean(!e.truthy());
    return let(RCompute::Not, {expr_of(e, "pair?")}, RType::Boolean);
  }
  return call_original("pair?", a, n);
}

Value P_list_list_p(Value *a, int n) {
  if (has_rtlist_tail(a[0])) return Value::boolean(true);
  return call_original("list?", a, n);
}

Value P_list_length(Value *a, int n) {
  long prefix = 0;
  Value v = a[0];
  for (; is_pair(v); v = cdr(v))
    ++prefix;
  if (RtList *r = as_rtlist(v)) return count_plus(list_count(r), prefix);
  return call_original("length", a, n);
}

Value P_list_reverse(Value *a, int n) {
  if (RtList *r = as_rtlist(a[0]))
    return make_rtlist(r->list, !r->reversed, false, r->start, r->end);
  if (has_rtlist_tail(a[0])) refuse_list(a[0], "reverse");
  return call_original("reverse", a, n);
}

Value P_list_ref(Value *a, int n) {
  if (RtList *r = as_rtlist(a[0])) return list_element(r, count_arg(a, 1, "list-ref"), "list-ref");
  if (is_dynamic_scalar(a[1]))
    cannot_compile(here(), "list-ref of a list known at compile time at an index known only at "
                           "run time");
  return call_original("list-ref", a, n);
}

Value P_list_tail(Value *a, int n) {
  if (RtList *r = as_rtlist(a[0])) return list_tail(r, count_arg(a, 1, "list-tail"));
  return call_original("list-tail", a, n);
}

Value P_list_last(Value *a, int n) {
  if (RtList *r = as_rtlist(a[0])) return list_element(r, count_plus(list_count(r), -1), "last");
  if (has_rtlist_tail(a[0])) refuse_list(a[0], "last");
  return call_original("last", a, n);
}

// c[ad]+r and first ... fifth: car and cdr one at a time, so that a run-time
// list met on the way is taken apart at run time.
template <const char *Name> Value P_list_cxr(Value *a, int n) {
  std::string_view name = Name;
  std::string ops; // applied right to left
  if (name[0] == 'c') {
    ops = std::string(name.substr(1, name.size() - 2));
  } else {
    static const char *const nth[] = {"first", "second", "third", "fourth", "fifth"};
    for (int k = 0; k < 5; ++k)
      if (name == nth[k]) ops = "a" + std::string(static_cast<size_t>(k), 'd');
  }
  // Only the cells on the path matter: (cadr l) of a long static list
  // walked all of l for run-time lists before, once per call, which made a
  // loop over the list quadratic (stdlib/stability.sicm's manifolds).
  Value v = a[0];
  bool run_time = as_rtlist(v) != nullptr;
  for (size_t i = ops.size(); i-- > 0 && !run_time && is_pair(v);) {
    v = ops[i] == 'a' ? car(v) : cdr(v);
    run_time = as_rtlist(v) != nullptr;
  }
  if (!run_time) return call_original(Name, a, n);
  v = a[0];
  for (size_t i = ops.size(); i-- > 0;) {
    Value arg[1] = {v};
    v = ops[i] == 'a' ? P_list_car(arg, 1) : P_list_cdr(arg, 1);
  }
  return v;
}

// (map f l ...) or (for-each f l ...) over run-time lists: a C loop over the
// positions, in which f is traced once on the elements (its statements run
// for each); map adds f's results to a new list.
Value map_over_lists(Value f, Value *lists, int nlists, bool collect, const char *who) {
  gcvec<Value> views(lists, lists + nlists);
  Value n = list_count(as_rtlist(views[0]));
  for (int k = 1; k < nlists; ++k) // the shortest list, as MIT's map
    n = let(RCompute::Min, {expr_of(n, who), expr_of(list_count(as_rtlist(views[k])), who)},
            RType::Integer);
  Value i = new_var(RType::Integer);
  RStmt loop{RKind::Loop};
  loop.outs = {var_of(i)};
  loop.args = {expr_integer(0)};
  std::vector<RStmt> body;
  gcvec<Assignment> log;
  Value result;
  {
    struct Scope { // the loop's body receives the statements
      Scope(std::vector<RStmt> *body, gcvec<Assignment> *log) {
        g_blocks.push_back(body);
        g_undo.push_back(log);
        g_undo_serials.push_back(g_frame_serial);
      }
      ~Scope() {
        g_blocks.pop_back();
        g_undo.pop_back();
        g_undo_serials.pop_back();
      }
    } scope(&body, &log);
    Value done = let(RCompute::LessEq, {expr_of(n, who), expr_of(i, who)}, RType::Boolean);
    RStmt stop{RKind::If};
    stop.args = {expr_of(done, who)};
    stop.then_body.emplace_back(RKind::Break);
    emit(std::move(stop));
    gcvec<Value> elements;
    for (Value v : views)
      elements.push_back(list_element(as_rtlist(v), i, who));
    result = apply_procedure(f, elements.data(), nlists);
  }
  if (!log.empty())
    cannot_compile(here(), std::string("set! inside the procedure given to ") + who +
                               " over a list whose length is known only at run time");
  int out = -1;
  if (collect) {
    gcvec<Value> leaves;
    if (!element_leaves(result, leaves))
      cannot_compile(here(), std::string("the procedure given to ") + who + " returns " +
                                 describe(result) +
                                 ", which cannot be an element of a list of run-time length");
    out = new_list(result, leaf_types(leaves), who);
    RStmt push{RKind::ListPush};
    push.list = out;
    for (Value leaf : leaves)
      push.args.push_back(expr_of(leaf, who));
    body.push_back(std::move(push));
  }
  RStmt next{RKind::Continue};
  next.outs = {var_of(i)};
  next.args = {expr_of(count_plus(i, 1), who)};
  body.push_back(std::move(next));
  loop.then_body = std::move(body);
  bool calls = block_calls(loop.then_body);
  current_block().push_back(std::move(loop));
  if (calls) read_cells();
  if (!collect) return Value::unspecified();
  return make_rtlist(out, true, false, Value::fixnum(0), n);
}

// ---- generalization: loops left for run time past the unroll limits ----------------------
//
// Evaluating a loop at compile time unrolls it: each iteration's run-time
// work (a state advancer's call, a plot mark) is a statement of its own, so
// the residual program grows with the iteration count. Past two named
// limits (limits.hpp; flags of sicm build) the partial evaluator
// generalizes instead, leaving the loop for run time (as Chez Scheme's cp0
// residualizes past its effort limits). Hitting a limit is never an error:
// if the generalized loop cannot be compiled (its body needs a value it now
// gets only at run time), the loop is unrolled as before.
//
//   kMaxUnrolledElements    map or for-each over lists known at compile time
//                           that are longer, of inexact numbers (or pairs or
//                           structures of them, all of one shape), whose
//                           procedure does run-time work on the first
//                           elements (an evaluation that is then forgotten
//                           records statements other than output text, or
//                           gives a run-time value): the lists become
//                           constant tables (RTable) copied into run-time
//                           lists, and the map a C loop over them
//                           (map_over_lists). Exact numbers stay known: they
//                           print differently from doubles.
//   kMaxUnrolledIterations  see "loops that start from known values" below.

// Undoes what evaluating something tentatively made: the statements go to
// `block`, assignments to older variables are logged, and roll_back forgets
// the variables, functions, lists and tables it made.
class Trial {
public:
  explicit Trial(std::vector<RStmt> *block)
      : nfunctions_(g_prog->functions.size()), nvars_(g_prog->vars.size()),
        nlists_(g_prog->lists.size()), ntables_(g_prog->tables.size()), nblocks_(g_blocks.size()),
        nundo_(g_undo.size()) {
    for (Value *place : list_cell_places())
      saved_lists_.push_back(*place);
    g_blocks.push_back(block);
    g_undo.push_back(&log_);
    g_undo_serials.push_back(g_frame_serial);
  }
  ~Trial() {
    g_blocks.resize(nblocks_);
    g_undo.resize(nundo_);
    g_undo_serials.resize(nundo_);
  }
  Trial(const Trial &) = delete;
  Trial &operator=(const Trial &) = delete;

  void roll_back() {
    for (auto a = log_.rbegin(); a != log_.rend(); ++a)
      *a->place = a->before;
    for (size_t v = nvars_; v < g_prog->vars.size(); ++v)
      g_var_of.erase(g_prog->vars[v].sym);
    g_prog->functions.resize(nfunctions_);
    g_prog->vars.resize(nvars_);
    g_prog->tables.resize(ntables_);
    bool lists_in_use = false; // by a list cell started meanwhile
    for (const ListCell &c : g_list_cells)
      lists_in_use = lists_in_use || c.list >= static_cast<int>(nlists_);
    if (!lists_in_use) {
      g_prog->lists.resize(nlists_);
      g_list_shapes.resize(nlists_);
      g_list_types.resize(nlists_);
    }
    std::vector<Value *> places = list_cell_places();
    for (size_t i = 0; i < saved_lists_.size() && i < places.size(); ++i)
      *places[i] = saved_lists_[i];
  }
  size_t nfunctions() const { return nfunctions_; }
  const gcvec<Assignment> &log() const { return log_; }

private:
  size_t nfunctions_, nvars_, nlists_, ntables_, nblocks_, nundo_;
  gcvec<Assignment> log_;
  gcvec<Value> saved_lists_;
};

// Keep what a Trial made, once it has ended: its statements follow in the
// current block, and an enclosing alternative or loop undoes its
// assignments too.
void keep_trial(std::vector<RStmt> &block, const gcvec<Assignment> &assigned) {
  if (!g_undo.empty())
    for (const Assignment &a : assigned)
      log_assignment(a);
  std::vector<RStmt> &to = current_block();
  for (RStmt &x : block) {
    if (x.kind == RKind::Text && !to.empty() && to.back().kind == RKind::Text)
      to.back().text += x.text;
    else
      to.push_back(std::move(x));
  }
}

// Does applying f to args record run-time work (statements other than
// output text, or a run-time result)? Evaluated and forgotten; false if it
// fails (it fails again, where the caller evaluates it for real).
bool does_run_time_work(Value f, gcvec<Value> args) {
  std::vector<RStmt> block;
  bool work = false;
  Trial trial(&block);
  try {
    Value r = apply_procedure(f, args.data(), static_cast<int>(args.size()));
    work = contains_dynamic(r) || g_prog->functions.size() > trial.nfunctions();
    for (const RStmt &s : block)
      work = work || s.kind != RKind::Text;
  } catch (const Error &) {
    work = false;
  } catch (...) {
    trial.roll_back();
    throw;
  }
  trial.roll_back();
  return work;
}

// An element a constant table can hold: an inexact number, or a pair or
// up/down structure of such elements (a list of them ends in ()).
bool inexact_tree(Value v, bool nil_ok) {
  if (v.is(Tag::Flonum)) return true;
  if (v.is(Tag::Nil)) return nil_ok;
  if (is_pair(v)) return inexact_tree(car(v), false) && inexact_tree(cdr(v), true);
  if (is_structure(v)) {
    Structure *st = as_structure(v);
    for (size_t i = 0; i < st->len; ++i)
      if (!inexact_tree(st->items[i], false)) return false;
    return st->len > 0;
  }
  return false;
}

// The first `count` elements of a list known at compile time as a table:
// their leaves in order, and the first element (the shape of all). False if
// they are not all inexact and of one shape.
bool table_of(Value list, long count, Value *shape, std::vector<double> &data) {
  Value x = list;
  for (long k = 0; k < count; ++k, x = cdr(x)) {
    Value e = car(x);
    if (!inexact_tree(e, false)) return false;
    if (k == 0) *shape = e;
    if (k > 0 && !same_shape(e, *shape)) return false;
    gcvec<Value> leaves;
    element_leaves(e, leaves);
    for (Value leaf : leaves)
      data.push_back(leaf.d);
  }
  return true;
}

// A run-time list holding a table's elements (shaped like `shape`), copied
// in where this statement runs.
Value constant_list(Value shape, std::vector<double> data, long count, const char *who) {
  gcvec<Value> leaves;
  element_leaves(shape, leaves);
  int width = static_cast<int>(leaves.size());
  int table = -1;
  for (size_t t = 0; t < g_prog->tables.size(); ++t)
    if (g_prog->tables[t].width == width && g_prog->tables[t].data == data)
      table = static_cast<int>(t);
  if (table < 0) {
    table = static_cast<int>(g_prog->tables.size());
    g_prog->tables.push_back(RTable{width, std::move(data)});
  }
  int id = static_cast<int>(g_prog->lists.size());
  g_prog->lists.push_back(RList{width, std::string("constant list for ") + who});
  g_list_shapes.push_back(element_shape(shape));
  g_list_types.push_back(std::vector<RType>(leaves.size(), RType::Real));
  RStmt s{RKind::ListConst};
  s.list = id;
  s.leaf = table;
  emit(std::move(s));
  return make_rtlist(id, true, false, Value::fixnum(0), Value::fixnum(count));
}

// (map f l ...) or (for-each f l ...) over lists known at compile time, as
// a C loop over constant tables when the lists are longer than
// --max-unrolled-elements and f does run-time work (see above); false to
// unroll it.
bool map_over_static_lists(Value *a, int n, bool collect, const char *who, Value *out) {
  uint64_t limit = current_limits().max_unrolled_elements;
  if (n < 2 || !is_procedure(a[0]) || limit == kUnlimited) return false;
  long count = -1;
  for (int k = 1; k < n; ++k) {
    long len = list_length(a[k]);
    if (len < 0) return false;
    count = count < 0 ? len : std::min(count, len);
  }
  if (count <= static_cast<long>(limit)) return false;
  gcvec<Value> shapes, firsts;
  std::vector<std::vector<double>> tables;
  for (int k = 1; k < n; ++k) {
    Value shape;
    tables.emplace_back();
    if (!table_of(a[k], count, &shape, tables.back())) return false;
    shapes.push_back(shape);
    firsts.push_back(car(a[k]));
  }
  if (!does_run_time_work(a[0], firsts)) return false;
  std::vector<RStmt> block;
  Value v;
  gcvec<Assignment> assigned;
  {
    Trial trial(&block);
    try {
      gcvec<Value> views;
      for (size_t k = 0; k < shapes.size(); ++k)
        views.push_back(constant_list(shapes[k], std::move(tables[k]), count, who));
      v = map_over_lists(a[0], views.data(), n - 1, collect, who);
      assigned = trial.log();
    } catch (const Error &) {
      trial.roll_back();
      return false; // unrolled: the error, if real, comes again
    } catch (...) {
      trial.roll_back();
      throw;
    }
  }
  keep_trial(block, assigned);
  *out = v;
  return true;
}

// ---- loops that start from known values -------------------------------------------------
//
// A named procedure called with known arguments runs at compile time, as in
// sicm run: a loop of 500 iterations that plots a point in each leaves 500
// plot statements. The outermost such call of a closure is watched (a
// Trial): if the closure calls itself with known arguments more than
// --max-unrolled-iterations (kMaxUnrolledIterations) times, and its calls
// recorded run-time work (statements other than output text) within the
// last half of that many calls, what the call did is forgotten and it is
// evaluated again as a loop from the first call (evaluate_as_loop with
// from_known): the known numbers that change from call to call become loop
// variables. A loop that computes only known values runs at compile time
// however long it is. If the call cannot be a loop (its recursive call is not
// in tail position, a count is used where a known value is needed, ...) it
// is evaluated as usual, unrolled, and no closure of its lambda is watched
// again.

struct StaticWatch {
  Closure *closure;
  uint64_t calls = 0;     // calls of the closure with known arguments while watched
  uint64_t work_mark = 0; // g_work when the current window of calls began
  int branch_depth = 0;   // g_branch_depth when the watch began
};

// A watched loop whose known calls nest this deep under tests on run-time
// values is left for run time at once: each iteration's test is one more
// level of alternatives, so unrolling it would end at kMaxBranchDepth (a
// Poincare-section refinement that halves its step 50 times, keeping its
// known state in the branch that halves and a run-time one in the other).
constexpr int kMaxWatchedBranchDepth = kMaxBranchDepth / 2;
struct UnrollLimit { // thrown to the watched call of `closure`
  Closure *closure;
};
std::vector<StaticWatch *> g_watches;
std::unordered_set<Lambda *> g_unrolled_lambdas; // whose loops could not be left for run time

// A call of c with known arguments: if c is watched, count it (and throw
// UnrollLimit past the limit) and say so.
bool count_known_call(Closure *c) {
  for (auto w = g_watches.rbegin(); w != g_watches.rend(); ++w) {
    StaticWatch &watch = **w;
    if (watch.closure != c) continue;
    if (g_branch_depth - watch.branch_depth >= kMaxWatchedBranchDepth) throw UnrollLimit{c};
    uint64_t limit = current_limits().max_unrolled_iterations;
    uint64_t window = std::max<uint64_t>(1, limit / 2);
    if (++watch.calls % window == 0) {
      if (watch.calls >= limit && g_work > watch.work_mark) throw UnrollLimit{c};
      watch.work_mark = g_work;
    }
    return true;
  }
  return false;
}

bool watch_known_call(Value f, Value *slots, long n, Value *out) {
  Closure *c = f.as<Closure>();
  if (current_limits().max_unrolled_iterations == kUnlimited || g_unrolled_lambdas.count(c->lambda))
    return false;
  StaticWatch watch{c, 0, g_work, g_branch_depth};
  std::vector<RStmt> block;
  Value v;
  gcvec<Assignment> assigned;
  bool limit_hit = false;
  {
    Trial trial(&block);
    g_watches.push_back(&watch);
    struct Pop {
      ~Pop() { g_watches.pop_back(); }
    } pop;
    gcvec<Value> args(slots, slots + n);
    try {
      v = apply_procedure(f, args.data(), static_cast<int>(n));
      assigned = trial.log();
    } catch (const UnrollLimit &u) {
      trial.roll_back();
      if (u.closure != c) throw;
      limit_hit = true;
    } catch (...) {
      trial.roll_back();
      throw;
    }
  }
  if (!limit_hit) {
    keep_trial(block, assigned);
    *out = v;
    return true;
  }
  if (evaluate_as_loop(f, slots, n, out, true)) return true;
  g_unrolled_lambdas.insert(c->lambda);
  return false;
}

template <const char *Name, bool Collect> Value P_list_map(Value *a, int n) {
  bool any = false, all = true;
  for (int k = 1; k < n; ++k) {
    bool rt = as_rtlist(a[k]) != nullptr;
    any = any || has_rtlist_tail(a[k]);
    all = all && rt;
  }
  if (!any) {
    Value v;
    if (map_over_static_lists(a, n, Collect, Name, &v)) return v;
    return call_original(Name, a, n);
  }
  if (!all)
    cannot_compile(here(), std::string(Name) + " over a list whose length is known only at run "
                                               "time together with other lists");
  if (!is_procedure(a[0])) wrong_type(a[0], 1, Name);
  return map_over_lists(a[0], a + 1, n - 1, Collect, Name);
}
constexpr char kMap[] = "map";
constexpr char kForEach[] = "for-each";

// (apply f x ... l) with l a run-time list (a holds f, x ... l): a fold when
// f is min, max, + or *.
Value apply_to_rtlist(Value *a, int n);

bool hook_apply_to_other(Value f, Value *args, long nargs, Value *out) {
  if (nargs < 1 || !has_rtlist_tail(args[nargs - 1])) return false;
  gcvec<Value> a{f};
  a.insert(a.end(), args, args + nargs);
  *out = apply_to_rtlist(a.data(), static_cast<int>(a.size()));
  return true;
}

Value apply_to_rtlist(Value *a, int n) {
  RtList *r = as_rtlist(a[n - 1]);
  static const char *const folds[] = {"min", "max", "+", "*"};
  int op = -1;
  for (int k = 0; k < 4; ++k) {
    Symbol *s = intern(folds[k]).symbol();
    if (s->bound && eq(s->global, a[0])) op = k;
  }
  if (op < 0 || !r || (n > 2 && op >= 2))
    cannot_compile(here(), "apply of " + describe(a[0]) +
                               " to a list whose length is known only at run time (only min, "
                               "max, + and * are compiled)");
  const std::vector<RType> &types = g_list_types[r->list];
  if (types.size() != 1 || types[0] == RType::Boolean || !is_scalar(g_list_shapes[r->list]))
    cannot_compile(here(), std::string("apply of ") + folds[op] + " to a list of " +
                               describe(g_list_shapes[r->list]) + ", not of numbers");
  Value v = new_var(types[0]);
  RStmt s{RKind::Let};
  s.compute = RCompute::ListFold;
  s.list = r->list;
  s.leaf = op;
  s.backward = !r->reversed;
  s.args = {expr_of(r->start, "apply"), expr_of(r->end, "apply")};
  s.var = var_of(v);
  emit(std::move(s));
  if (n == 2) return v;
  gcvec<Value> args(a + 1, a + n - 1);
  args.push_back(v);
  return apply_procedure(a[0], args.data(), static_cast<int>(args.size()));
}

// List procedures not compiled for run-time lists: a clear error.
template <const char *Name> Value P_list_refused(Value *a, int n) {
  for (int k = 0; k < n; ++k)
    if (contains_rtlist(a[k])) refuse_list(a[k], Name);
  return call_original(Name, a, n);
}

const DynamicBranchHooks kHooks = {hook_dynamic_test,  hook_branch,    hook_logic,
                                   hook_set_global,    hook_set_local, hook_call_closure,
                                   hook_apply_to_other};

void rebind(const char *name, int min, int max, PrimFn fn) {
  Symbol *s = intern(name).symbol();
  if (s->bound && s->global.is(Tag::Primitive)) g_original[name] = s->global.as<Primitive>()->fn;
  define_primitive(name, min, max, fn);
}

template <const char *Name> void rebind_cxr() {
  rebind(Name, 1, 1, P_list_cxr<Name>);
}
constexpr char kCaar[] = "caar", kCadr[] = "cadr", kCdar[] = "cdar", kCddr[] = "cddr",
               kCaddr[] = "caddr", kCdddr[] = "cdddr", kCadddr[] = "cadddr", kFirst[] = "first",
               kSecond[] = "second", kThird[] = "third", kFourth[] = "fourth", kFifth[] = "fifth";

void rebind_cxrs() {
  rebind_cxr<kCaar>();
  rebind_cxr<kCadr>();
  rebind_cxr<kCdar>();
  rebind_cxr<kCddr>();
  rebind_cxr<kCaddr>();
  rebind_cxr<kCdddr>();
  rebind_cxr<kCadddr>();
  rebind_cxr<kFirst>();
  rebind_cxr<kSecond>();
  rebind_cxr<kThird>();
  rebind_cxr<kFourth>();
  rebind_cxr<kFifth>();
}

// The list primitives that refuse run-time lists, with their arities.
template <const char *Name> void refuse(int min, int max) {
  Symbol *s = intern(Name).symbol();
  if (s->bound && s->global.is(Tag::Primitive)) rebind(Name, min, max, P_list_refused<Name>);
}
constexpr char kAppend[] = "append", kListCopy[] = "list-copy", kListToVector[] = "list->vector",
               kSort[] = "sort", kFilter[] = "filter", kReduce[] = "reduce",
               kFoldLeft[] = "fold-left", kFoldRight[] = "fold-right", kListHead[] = "list-head",
               kSublist[] = "sublist", kLastPair[] = "last-pair", kMember[] = "member",
               kMemv[] = "memv", kAssoc[] = "assoc", kAppendMap[] = "append-map",
               kEqualP[] = "equal?";

void rebind_refused() {
  refuse<kAppend>(0, kVariadic);
  refuse<kListCopy>(1, 1);
  refuse<kListToVector>(1, 1);
  refuse<kSort>(2, 2);
  refuse<kFilter>(2, 2);
  refuse<kReduce>(3, 3);
  refuse<kFoldLeft>(3, kVariadic);
  refuse<kFoldRight>(3, kVariadic);
  refuse<kListHead>(2, 2);
  refuse<kSublist>(3, 3);
  refuse<kLastPair>(1, 1);
  refuse<kMember>(2, 3);
  refuse<kMemv>(2, 2);
  refuse<kAssoc>(2, 3);
  refuse<kAppendMap>(2, kVariadic);
  refuse<kEqualP>(2, 2);
}

Value prepare_toplevel(Value v) {
  return prepare_for_print(v);
}

} // namespace

void begin_build_mode(ResidualProgram *program) {
  // Divisions by matrices of run-time values outside kernels compute as
  // the interpreter does (algebra/linear_solve.hpp).
  set_run_time_value_test(is_dynamic_scalar);
  g_blocks = {nullptr};
  g_bottom = Value::object(Tag::Opaque, gc_new<Opaque>(Opaque{&kBottomKind, nullptr}));
  g_prog = program;
  RFunction main_fn;
  main_fn.id = 0;
  main_fn.parent = -1;
  main_fn.name = "main";
  program->functions.push_back(std::move(main_fn));
  g_open = {0};
  g_advancer_lambda.name = intern("state-advancer").symbol();
  g_evolver_lambda.name = intern("evolve").symbol();

  rebind("display", 1, 2, P_print<kDisplay>);
  rebind("write", 1, 2, P_print<kWrite>);
  rebind("write-line", 1, 2, P_print<kWriteLine>);
  rebind("pp", 1, 2, P_print<kPp>);
  rebind("print-expression", 1, 1, P_print<kPrintExpression>);
  rebind("pe", 1, 1, P_print<kPe>);
  rebind("<", 1, kVariadic, P_compare<kLess, RCompute::Less, false>);
  rebind(">", 1, kVariadic, P_compare<kGreater, RCompute::Less, true>);
  rebind("<=", 1, kVariadic, P_compare<kLessEq, RCompute::LessEq, false>);
  rebind(">=", 1, kVariadic, P_compare<kGreaterEq, RCompute::LessEq, true>);
  rebind("=", 1, kVariadic, P_compare<kEqual, RCompute::Equal, false>);
  rebind("zero?", 1, 1, P_sign_test<kZero, RCompute::Equal, false>);
  rebind("positive?", 1, 1, P_sign_test<kPositive, RCompute::Less, true>);
  rebind("negative?", 1, 1, P_sign_test<kNegative, RCompute::Less, false>);
  rebind("floor", 1, 1, P_unary<kFloor, RCompute::Floor>);
  rebind("round", 1, 1, P_unary<kRound, RCompute::Round>);
  rebind("truncate", 1, 1, P_unary<kTruncate, RCompute::Truncate>);
  rebind("max", 1, kVariadic, P_fold<kMax, RCompute::Max>);
  rebind("min", 1, kVariadic, P_fold<kMin, RCompute::Min>);
  rebind("not", 1, 1, P_not);
  rebind("real-time", 0, 0, P_real_time);
  rebind("parameter", 2, 2, P_parameter);
  rebind("runtime", 0, 0, P_runtime);
  rebind("number?", 1, 1, P_number_test<kNumberP>);
  rebind("real?", 1, 1, P_number_test<kRealP>);
  rebind("inexact?", 1, 1, P_number_test<kInexactP>);
  rebind("exact?", 1, 1, P_number_test<kExactP>);
  rebind("integer?", 1, 1, P_number_test<kIntegerP>);
  rebind("exact-integer?", 1, 1, P_number_test<kExactIntegerP>);
  rebind("exact-nonnegative-integer?", 1, 1, P_number_test<kExactNonnegP>);
  rebind("exact-rational?", 1, 1, P_number_test<kExactRationalP>);
  rebind("exact->inexact", 1, 1, P_identity_on_dynamic<kExactToInexact>);
  rebind("inexact", 1, 1, P_identity_on_dynamic<kInexact>);

  rebind("definite-integral", 3, 5, retrying<P_definite_integral>);
  rebind("minimize", 3, 4, retrying<P_minimize<kMinimize>>);
  rebind("brent-min", 3, 4, retrying<P_minimize<kBrentMin>>);
  rebind("multidimensional-minimize", 2, 3, retrying<P_multidimensional_minimize>);
  rebind("find-root", 3, 4, retrying<P_find_root>);
  rebind("nelder-mead", 2, 5, P_not_yet);
  rebind("bisect", 4, 5, retrying<P_bisect>);
  rebind("state-advancer", 1, kVariadic, P_state_advancer);
  rebind("evolve", 1, kVariadic, P_evolve);
  rebind("frame", 4, 7, P_frame);
  rebind("plot-point", 3, 3, P_plot_point);
  rebind("plot-line", 5, 5, P_plot_line);
  rebind("graphics-close", 1, 1, P_graphics_close);
  rebind("graphics-clear", 1, 1, P_graphics_clear);

  rebind("car", 1, 1, P_list_car);
  rebind("cdr", 1, 1, P_list_cdr);
  rebind("null?", 1, 1, P_list_null);
  rebind("pair?", 1, 1, P_list_pair);
  rebind("list?", 1, 1, P_list_list_p);
  rebind("length", 1, 1, P_list_length);
  rebind("reverse", 1, 1, P_list_reverse);
  rebind("list-ref", 2, 2, P_list_ref);
  rebind("list-tail", 2, 2, P_list_tail);
  rebind("last", 1, 1, P_list_last);
  rebind("map", 2, kVariadic, P_list_map<kMap, true>);
  rebind("for-each", 2, kVariadic, P_list_map<kForEach, false>);
  rebind_cxrs();
  rebind_refused();

  set_output_hook(residual_output);
  set_print_preparer(prepare_toplevel);
  g_dynamic_branch_hooks = &kHooks;
}

} // namespace sicm
