// `sicm build`'s numerical primitives: definite-integral, minimize,
// multidimensional-minimize, find-root, bisect, state-advancer, evolve and
// crossings record a statement of the residual program and return fresh run-time
// values. The procedures they are given (an integrand, an objective, a
// system derivative, a monitor) are traced into functions of the residual
// program, which the statement calls. Part of build mode (the design is in
// pe/build_mode.cpp; the shared declarations in pe/state.hpp).
#include <cmath>
#include <exception>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "algebra/generic.hpp"
#include "algebra/linear_solve.hpp"
#include "algebra/structure.hpp"
#include "algebra/symbolic.hpp"
#include "base/limits.hpp"
#include "base/number.hpp"
#include "base/primitive.hpp"
#include "builtins/crossing_events.hpp"
#include "builtins/integration_errors.hpp"
#include "builtins/numeric_arguments.hpp"
#include "builtins/numerics.hpp"
#include "builtins/numerics_defaults.hpp"
#include "codegen/emit_taylor.hpp"
#include "codegen/kernel_form.hpp"
#include "codegen/singular_factors.hpp"
#include "codegen/state_shape.hpp"
#include "codegen/trace.hpp"
#include "eval/procedure.hpp"
#include "pe/specialized.hpp"
#include "pe/state.hpp"
#include "print/printer.hpp"
#include "sicm/runtime.h"

namespace sicm::build {

namespace {

// ---- tracing procedures into functions ------------------------------------------------

// Opens a function for the duration of a trace.
class FunctionScope {
public:
  FunctionScope(const std::string &name) {
    RFunction f;
    f.id = static_cast<int>(g_build->program.functions.size());
    f.parent = g_build->open.back();
    f.name = name;
    f.loc = here();
    g_build->program.functions.push_back(std::move(f));
    g_build->open.push_back(g_build->program.functions.back().id);
    g_build->blocks.push_back(nullptr);
    g_build->function_serials.push_back(g_frame_serial);
    saved_depth_ = g_build->branch_depth;
    g_build->branch_depth = 0; // a test inside the traced procedure is its own
    for (const RCell &c : g_build->program.cells)
      saved_.push_back(*c.place);
    for (Value *place : list_cell_places())
      saved_lists_.push_back(place ? *place : Value::nil());
    read_cells();
  }
  ~FunctionScope() {
    g_build->open.pop_back();
    g_build->blocks.pop_back();
    g_build->function_serials.pop_back();
    g_build->branch_depth = saved_depth_;
    for (size_t i = 0; i < saved_.size() && i < g_build->program.cells.size(); ++i)
      *g_build->program.cells[i].place = saved_[i];
    std::vector<Value *> places = list_cell_places();
    for (size_t i = 0; i < saved_lists_.size() && i < places.size(); ++i)
      *places[i] = saved_lists_[i];
  }
  int id() const { return g_build->open.back(); }

private:
  int saved_depth_;
  gcvec<Value> saved_;       // the cells' globals as the caller sees them
  gcvec<Value> saved_lists_; // the list cells' variables
};

} // namespace

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

namespace {

// ---- kernels: traced as sicm run traces them ------------------------------------------
//
// A system derivative (and its Jacobian) is traced as sicm run's
// trace_procedure traces a kernel (codegen/trace.hpp), so that both modes
// compute it with the same operations in the same order: its inputs are
// named x0, x1, ... as sicm run's (the simplifier orders symbols by name),
// and the numbers and captured run-time values that meet them become
// parameters k0, k1, ... (KernelParameters, algebra/symbolic.hpp), here
// variables of the calling function defined just before the call, which
// the traced function captures as sicm run's kernel reads p[].

// A value shaped like `sample` whose leaves are fresh inputs of the current
// function named as trace_procedure names a kernel's inputs.
Value kernel_input_like(Value sample) {
  gcvec<Value> leaves;
  state_leaves(sample, leaves);
  for (Value &leaf : leaves) {
    leaf = new_var(RType::Real, "x" + std::to_string(current().inputs.size()));
    current().inputs.push_back(var_of(leaf));
  }
  return state_from_leaves(sample, leaves);
}

// Where the parameters of the kernel being traced are defined: the block the
// caller was in when the trace began (an index into g_build->blocks, whose
// entry may be null for the function's body).
struct ParameterSite {
  int traced;   // the traced function; its vars and those of functions after it are its own
  int parent;   // the function that calls it
  size_t block; // g_build->blocks.size() before the trace's function opened
  std::unordered_set<int> parameters;        // the variables define_parameter made
  std::unordered_map<ExprId, bool> captured; // memo of is_captured
};
ParameterSite *g_site = nullptr;

std::vector<RStmt> &caller_block(const ParameterSite &site) {
  std::vector<RStmt> *b = site.block > 0 ? g_build->blocks[site.block - 1] : nullptr;
  return b ? *b : g_build->program.functions[site.parent].body;
}

// Does the expression mention no variable of the traced function?
bool only_outer_variables(ExprId root, ParameterSite &site) {
  auto hit = site.captured.find(root);
  if (hit != site.captured.end()) return hit->second;
  bool outer = true;
  const ExprNode &n = expr_node(root);
  if (n.kind == ExprKind::Symbol) {
    auto v = g_build->var_ids.find(n.sym);
    outer = v != g_build->var_ids.end() &&
            g_build->program.vars[v->second].function < site.traced &&
            !site.parameters.count(v->second);
  } else if (n.kind == ExprKind::Apply || n.kind == ExprKind::Call) {
    for (ExprId a : expr_arg_vector(root))
      if (!(outer = only_outer_variables(a, site))) break;
  }
  site.captured[root] = outer;
  return outer;
}

bool is_captured(Value v) {
  return g_site && is_dynamic_scalar(v) && only_outer_variables(expr_of(v, "kernel"), *g_site);
}

// Parameter `sym` (its value `value`) as a variable of the caller, defined
// in the caller's block. Done once the trace is over: made during the trace,
// a variable would be undone by the rollbacks of attempts inside it (a loop
// tried as a C loop) while the trace's parameters still named it.
void define_parameter(Symbol *sym, Value value) {
  ParameterSite &site = *g_site;
  int id = static_cast<int>(g_build->program.vars.size());
  g_build->program.vars.push_back(RVar{sym, RType::Real, id, site.parent});
  g_build->var_ids[sym] = id;
  site.parameters.insert(id);
  g_build->parameter_values[expr_symbol(sym)] = value.is(Tag::Flonum)
                                                    ? expr_from_number(decimal_rational(value.d))
                                                    : expr_of(value, "kernel");
  RStmt s{RKind::Let};
  s.loc = here();
  s.compute = RCompute::Expr;
  s.args = {expr_of(value, "kernel")};
  s.var = id;
  caller_block(site).push_back(std::move(s));
}

// The site of a kernel trace while it lives; rollback() forgets what the
// trace made (a Checkpoint), as it must when an exception leaves the scope
// (a retrace, a failed trace: the parameters' definitions in the caller's
// block go with the variables).
class KernelTraceScope {
public:
  KernelTraceScope() : outer_(g_site), exceptions_(std::uncaught_exceptions()) {
    site_.traced = static_cast<int>(g_build->program.functions.size());
    site_.parent = g_build->open.back();
    site_.block = g_build->blocks.size();
    g_site = &site_;
  }
  ~KernelTraceScope() {
    if (std::uncaught_exceptions() > exceptions_) rollback();
    g_site = outer_;
  }
  void rollback() { checkpoint_.restore(); }

private:
  Checkpoint checkpoint_; // the caller's block is the current one
  ParameterSite site_;
  ParameterSite *outer_;
  int exceptions_;
};

// proc applied to x as sicm run's kernels are traced, with parameters,
// which are then defined in the caller.
Value apply_kernel_traced(Value proc, gcvec<Value> x) {
  Value result;
  gcvec<Symbol *> symbols;
  gcvec<Value> values;
  {
    KernelParameters params(is_captured);
    result = apply_traced(proc, std::move(x));
    symbols = params.symbols;
    values = params.values;
  }
  for (size_t j = 0; j < symbols.size(); ++j)
    define_parameter(symbols[j], values[j]);
  return result;
}

} // namespace

bool is_state_shape(Value v) {
  if (is_number(v) || is_dynamic_scalar(v)) return true;
  size_t len;
  Value *items = container_items(v, &len);
  if (!items || len == 0) return false;
  for (size_t i = 0; i < len; ++i)
    if (!is_state_shape(items[i])) return false;
  return true;
}

std::string procedure_name(Value proc) {
  if (proc.is(Tag::Closure) && proc.as<Closure>()->lambda->name)
    return proc.as<Closure>()->lambda->name->name;
  return "anonymous";
}

int in_new_function(const std::string &name, const std::function<void()> &body) {
  FunctionScope scope(name);
  body();
  return scope.id();
}

namespace {

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

} // namespace

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

namespace {

// ---- numerical primitives ---------------------------------------------------------------

// A numerical primitive run by with_retrace.
template <PrimFn F> Value retrying(Value *a, int n) {
  return with_retrace([&] { return F(a, n); });
}

template <NativeFn F> Value retrying_native(NativeProc *self, Value *a, int n) {
  return with_retrace([&] { return F(self, a, n); });
}

double static_number(Value *a, int n, int i, double fallback, const char *who) {
  if (i >= n || a[i].is(Tag::Default)) return fallback;
  if (!is_number(a[i])) {
    if (is_dynamic_scalar(a[i]))
      cannot_compile(here(), std::string(who) + "'s tolerance must be known at compile time");
    wrong_type(a[i], i + 1, who);
  }
  return to_double(a[i]);
}

// An optional count at a[i] that check_numeric_arguments checked (an
// exact integer, known now), or 0 when it is missing.
long static_count(Value *a, int n, int i) {
  return i >= n || a[i].is(Tag::Default) ? 0 : a[i].i;
}

ExprId limit_expr(Value v, const char *who) {
  if (is_symbol(v) && var_of(v) < 0) {
    const std::string &s = symbol_name(v);
    if (s == ":+infinity" || s == "+infinity") return expr_flonum(INFINITY);
    if (s == ":-infinity" || s == "-infinity") return expr_flonum(-INFINITY);
  }
  return expr_of(v, who);
}

// Each primitive first checks its arguments with sicm run's function
// (check_numeric_arguments, builtins/numeric_arguments.hpp): the same
// mistake gets the same message in both modes.
Value P_definite_integral(Value *a, int n) {
  static const char who[] = "definite-integral";
  check_numeric_arguments(who, a, n);
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
  check_numeric_arguments(Name, a, n);
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
  check_numeric_arguments(who, a, n);
  bool is_list = !a[1].is(Tag::Vector);
  gcvec<Value> start;
  if (is_list) {
    start = list_to_vector(a[1]);
  } else {
    Vector *v = a[1].vector();
    start.assign(v->items, v->items + v->len);
  }
  RStmt s{RKind::Multimin};
  s.as_list = is_list;
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
  check_numeric_arguments(who, a, n);
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

Value bisect_at_run_time(Value *a, int n) {
  static const char who[] = "bisect";
  check_numeric_arguments(who, a, n);
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

// A numerical primitive whose result cannot be left for run time, computed
// while compiling by the interpreter's `name`, as sicm run computes it: the
// program keeps the number, and an error of the program is raised as sicm
// run raises it. Where the function reads values known only at run time it
// cannot be computed now either; what the program added is rewound and
// `why_not` says so.
Value computed_while_compiling(const char *name, Value *a, int n,
                               const std::function<void()> &why_not) {
  Checkpoint mark;
  try {
    return call_original(name, a, n);
  } catch (const Error &e) {
    if (!is_cannot_compile(e)) throw;
    mark.restore();
  }
  why_not();
  SICM_ASSERT(false); // why_not throws
  return Value::unspecified();
}

// A numerical primitive whose procedure cannot be compiled for run time
// (bisect's which-way? of section 4.6.1 builds streams and lists it
// mutates; an objective may return a symbol) but whose numbers are all
// known now is computed while compiling, by sicm run's own primitive: the
// program keeps its result, or fails where and as sicm run fails.
template <PrimFn AtRunTime, const char *Name> Value traced_or_computed(Value *a, int n) {
  bool known = true;
  for (int i = 1; i < n; ++i)
    known = known && !holds_run_time_value(a[i]);
  Checkpoint mark;
  const SrcLoc call = current_call_loc(); // the trace moves it into the function
  try {
    return AtRunTime(a, n);
  } catch (const Error &e) {
    if (!known || !is_cannot_compile(e)) throw;
    mark.restore();
    reset_call_loc(call);
    Error why = e;
    return computed_while_compiling(Name, a, n, [&] { throw why; });
  }
}
constexpr char kDefiniteIntegral[] = "definite-integral";
constexpr char kMultidimensionalMinimize[] = "multidimensional-minimize";
constexpr char kFindRoot[] = "find-root";
constexpr char kBisect[] = "bisect";

// nelder-mead is not compiled for run time: it is computed while compiling.
Value P_nelder_mead(Value *a, int n) {
  return computed_while_compiling("nelder-mead", a, n, [] {
    cannot_compile(here(), "nelder-mead is not compiled for run time, and its function reads "
                           "values known only at run time");
  });
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
                              ", which names no integrator (" + integrator_list() + ")");
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
  if (n.kind == ExprKind::Symbol) return g_build->var_ids.count(n.sym) > 0;
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

// Every function opens with reads of the cells that set! made and of the
// lengths of lists a monitor builds (read_cells, pe/build_mode.cpp); a
// system derivative that uses none of them, beside a
// monitor that counts with set!, is still one DAG of its state: the reads
// are dropped, so that it is a kernel, as in sicm run, and has Taylor
// coefficients.
void drop_unused_cell_reads(RFunction &f) {
  std::unordered_set<Symbol *> used;
  std::vector<ExprId> stack(f.outputs.begin(), f.outputs.end());
  std::unordered_set<ExprId> seen;
  while (!stack.empty()) {
    ExprId id = stack.back();
    stack.pop_back();
    if (!seen.insert(id).second) continue;
    const ExprNode &n = expr_node(id);
    if (n.kind == ExprKind::Symbol) used.insert(n.sym);
    if (n.kind == ExprKind::Apply || n.kind == ExprKind::Call) {
      const ExprId *args = expr_args(id);
      stack.insert(stack.end(), args, args + n.nargs);
    }
  }
  for (const RStmt &s : f.body)
    if (s.kind != RKind::Let ||
        (s.compute != RCompute::ReadCell && s.compute != RCompute::ListLength) ||
        used.count(g_build->program.vars[s.var].sym))
      return;
  f.body.clear();
}

// A traced system derivative, Jacobian or singular-factor function that is
// one DAG of its inputs is a kernel (RFunction::kernel): plain C, as sicm
// run's JIT kernels.
void mark_if_kernel(RFunction &f) {
  drop_unused_cell_reads(f);
  f.kernel = f.body.empty();
}

} // namespace

namespace {

// v with each number made a flonum, as an integrator holds a state.
Value inexact_leaves(Value v) {
  if (is_number(v)) return Value::flonum(to_double(v));
  if (is_structure(v)) {
    Structure *s = as_structure(v);
    gcvec<Value> items(s->items, s->items + s->len);
    for (Value &x : items)
      x = inexact_leaves(x);
    return make_structure_from(s->up, items.data(), items.size());
  }
  if (v.is(Tag::Vector)) {
    Vector *w = v.vector();
    Value r = make_vector(w->len, Value::unspecified());
    for (size_t i = 0; i < w->len; ++i)
      r.vector()->items[i] = inexact_leaves(w->items[i]);
    return r;
  }
  return v;
}

// Thrown out of the trace when the derivative's value is not shaped like a
// state known now (see trace_system_function).
struct NotShapedLikeState {};

} // namespace

namespace {

// While it lives, the procedure being traced is one whose values end as
// doubles (select_values in pe/branches.cpp).
struct DoublesOnly {
  DoublesOnly() { ++g_build->doubles_only; }
  ~DoublesOnly() { --g_build->doubles_only; }
  DoublesOnly(const DoublesOnly &) = delete;
  DoublesOnly &operator=(const DoublesOnly &) = delete;
};

} // namespace

// A system derivative traced into a new function of the state's leaves
// whose outputs are the derivative's leaves, in the form the interpreter's
// compiled derivatives take (kernel_outputs: evolve in `sicm run` compiles
// the same kernel, so both compute the same numbers). Returns its id.
//
// A value not shaped like the state is sicm run's error at the call
// (derivative_shape_error), certain when the state is known now: the
// derivative's value on the state as the integrator holds it (leaves made
// flonums), computed once the trace is left, is not shaped like it either.
// Else the message would need numbers known only at run time: cannot
// compile.
int trace_system_function(Value sysder, Value state, const char *who) {
  if (!is_state_shape(state)) wrong_type(state, 1, who);
  SrcLoc call = here(); // the integrator's call: the trace moves into sysder
  DoublesOnly doubles;
  try {
    KernelTraceScope parameters;
    FunctionScope scope(procedure_name(sysder));
    gcvec<Value> x{kernel_input_like(state)};
    Value d = apply_kernel_traced(sysder, x); // as sicm run traces its kernels
    gcvec<Value> leaves;
    if (!derivative_leaves(d, state, leaves, is_scalar_leaf)) {
      if (!contains_dynamic(state)) throw NotShapedLikeState{};
      cannot_compile(call, std::string("the system derivative passed to ") + who + " returns " +
                               describe(d) + ", which is not shaped like the state " +
                               describe(state));
    }
    std::vector<ExprId> outputs = system_outputs(leaves, who);
    current().outputs.insert(current().outputs.end(), outputs.begin(), outputs.end());
    mark_if_kernel(current());
    return scope.id();
  } catch (const NotShapedLikeState &) {
    Value held = inexact_leaves(state);
    derivative_shape_error(call, who, apply_procedure(sysder, &held, 1), held);
  }
}

// An event traced into a new function of the state's leaves with one
// output, the event's value, computing as the interpreter computes (the
// event is interpreted in sicm run until it proves worth compiling, and
// then compiled from this same trace: pe/for_run.cpp). Returns its id.
int trace_event_function(Value event, Value state, const char *who) {
  SrcLoc call = here();
  FunctionScope scope(procedure_name(event));
  Value x = input_like(state);
  Value g = apply_procedure(event, &x, 1);
  if (!is_number(g) && !is_dynamic_scalar(g))
    cannot_compile(call, std::string(who) + ": the event procedure returns " + describe(g) +
                             ", not a number");
  current().outputs.push_back(expr_of(g, who));
  return scope.id();
}

namespace {

// Trace a system derivative on a state shaped like `state`; fills the
// statement's callee, time_first and rate_one.
void trace_system(Value sysder, Value state, RStmt &s, const char *who) {
  s.callee = trace_system_function(sysder, state, who);
  size_t len;
  Value *items = container_items(state, &len);
  s.time_first = items && !container_items(items[0], &len);
  ExprId d0 = g_build->program.functions[s.callee].outputs[0];
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
  const RFunction &f = g_build->program.functions[s.callee];
  if (!f.body.empty()) taylor_refused(s.loc, who, method, TaylorRefusal::NotOneExpression);
  Trace t;
  for (int v : f.inputs)
    t.inputs.push_back(g_build->program.vars[v].sym);
  t.outputs = f.outputs;
  std::string why_not;
  auto any_symbol = [](Symbol *) { return std::string("p[0]"); };
  if (emit_taylor_function(t, "check", &why_not, TaylorPrecision::Double, any_symbol).empty())
    taylor_refused(s.loc, who, method, TaylorRefusal::NoRecurrence, why_not);
}

// What the system derivative divides by, as a function of its own inputs
// (the same state's leaves), for the runtime to name where an integration
// fails (codegen/singular_factors.hpp).
void trace_singular_factors(Value state, RStmt &s) {
  std::vector<Symbol *> from;
  for (int v : g_build->program.functions[s.callee].inputs)
    from.push_back(g_build->program.vars[v].sym);
  std::vector<std::string> paths = state_leaf_paths(state, "state");
  std::unordered_map<Symbol *, std::string> names;
  for (size_t i = 0; i < from.size() && i < paths.size(); ++i)
    names[from[i]] = paths[i];
  SingularFactors factors = singular_factors(
      with_leaves(g_build->program.functions[s.callee].outputs, g_build->parameter_values),
      [&](Symbol *sym) {
        auto it = names.find(sym);
        return it == names.end() ? std::string() : it->second;
      });
  if (factors.values.empty()) return;
  FunctionScope scope("singular_factors");
  input_like(state);
  std::vector<Symbol *> to;
  for (int v : current().inputs)
    to.push_back(g_build->program.vars[v].sym);
  current().outputs = with_inputs(factors.values, from, to);
  mark_if_kernel(current());
  s.probe = scope.id();
  s.probe_texts = std::move(factors.texts);
}

// For the implicit methods, the Jacobian (D sysder) traced as a function of
// the state too (its leaves: d f_i / d y_j at j * dim + i), as sicm run
// compiles it; left to finite differences when it cannot be traced, and,
// as sicm run leaves it (builtins/numerics.cpp), when the derivative is not
// a kernel: one that tests the state (whose Jacobian D now traces through
// the test) integrates with the same steps in both.
void trace_jacobian(Value sysder, Value state, RStmt &s) {
  if (s.method != "sicm_ode_step_msbdf" && s.method != "sicm_ode_step_cvode_bdf") return;
  if (s.callee < 0 || !g_build->program.functions[s.callee].kernel) return;
  Symbol *d = intern("D").symbol();
  if (!d->bound) return;
  DoublesOnly doubles;
  KernelTraceScope parameters;
  try {
    FunctionScope scope("jacobian");
    Value dsys = apply_procedure(d->global, &sysder, 1);
    gcvec<Value> x{kernel_input_like(state)};
    Value j = apply_kernel_traced(dsys, x);
    gcvec<Value> leaves;
    state_leaves(j, leaves);
    size_t n = current().inputs.size();
    if (leaves.size() != n * n) return;
    std::vector<ExprId> outputs = system_outputs(leaves, "jacobian");
    current().outputs.insert(current().outputs.end(), outputs.begin(), outputs.end());
    mark_if_kernel(current());
    s.jacobian = scope.id();
  } catch (const Error &) {
    parameters.rollback();
    s.jacobian = -1;
  }
}

bool has_exact_leaf(Value state) {
  gcvec<Value> leaves;
  state_leaves(state, leaves);
  for (Value leaf : leaves)
    if (is_number(leaf) && is_exact(leaf)) return true;
  return false;
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

Value make_named(NativeFn fn, Value sysder, Lambda *lambda) {
  Value p = make_native_procedure(fn, 0, sysder, Value::nil());
  static_cast<NativeProc *>(p.as<Opaque>()->obj)->print_as.lambda = lambda;
  return p;
}

Value sysder_of(Value *a, int n, const char *who) {
  if (n < 1 || !is_procedure(a[0])) wrong_type(n < 1 ? Value::nil() : a[0], 1, who);
  return apply_procedure(a[0], a + 1, n - 1);
}

// The events after the other arguments (on-crossing, stop-on-crossing,
// a[n .. all)): each event traced as crossings' is, each procedure as a
// monitor is, into functions the statement calls at run time.
void trace_events(Value *a, int n, int all, Value state, RStmt &s, const char *who) {
  for (int i = n; i < all; ++i) {
    const CrossingEvent *e = as_crossing_event(a[i]);
    reset_call_loc(s.loc); // the traces before moved it into their procedures
    REvent r;
    r.event = trace_event_function(e->event, state, who);
    r.direction = crossing_direction(*e);
    if (!e->stops()) {
      FunctionScope scope(procedure_name(e->action));
      Value x = input_like(state);
      apply_procedure(e->action, &x, 1);
      r.action = scope.id();
    }
    s.events.push_back(r);
  }
}

Value advance(NativeProc *self, Value *a, int all) {
  static const char who[] = "state-advancer";
  const int n = arguments_before_events(a, all, 2, who);
  check_numeric_arguments(who, a, n, self);
  RStmt s{RKind::Advance};
  s.loc = here();
  s.number = static_number(a, n, 2, kAdvancerTolerance, who);
  s.method = method_of(a, n, 3, who);
  check_reachable_tolerance(s.loc, who, integrator_of_c_name(s.method), s.number);
  s.max_steps = static_count(a, n, 4);
  state_args(a[0], s, who);
  s.args.push_back(expr_of(a[1], who));
  trace_system(self->a, a[0], s, who);
  check_taylor(s, who);
  trace_singular_factors(a[0], s);
  trace_jacobian(self->a, a[0], s);
  trace_events(a, n, all, a[0], s, who);
  Value r = state_result(a[0], s);
  emit(std::move(s));
  return r;
}

Value P_state_advancer(Value *a, int n) {
  return make_named(retrying_native<advance>, sysder_of(a, n, "state-advancer"),
                    &g_build->advancer_lambda);
}

Value run_evolve(NativeProc *self, Value *a, int all) {
  static const char who[] = "evolve";
  const int n = arguments_before_events(a, all, 4, who);
  check_numeric_arguments(who, a, n, self);
  check_monitor_arity(here(), who, a[1]);
  Checkpoint before; // for a monitor whose trace fails (below)
  RStmt s{RKind::Evolve};
  s.loc = here();
  s.number = static_number(a, n, 4, kAdvancerTolerance, who);
  s.method = method_of(a, n, 5, who);
  check_reachable_tolerance(s.loc, who, integrator_of_c_name(s.method), s.number);
  s.max_steps = static_count(a, n, 6);
  state_args(a[0], s, who);
  s.args.push_back(expr_of(a[2], who));
  s.args.push_back(expr_of(a[3], who));
  trace_system(self->a, a[0], s, who);
  check_taylor(s, who);
  trace_singular_factors(a[0], s);
  trace_jacobian(self->a, a[0], s);
  Value monitor = a[1];
  try {
    FunctionScope scope(procedure_name(monitor));
    Value x = input_like(a[0]);
    apply_procedure(monitor, &x, 1);
    s.monitor = scope.id();
  } catch (const Error &e) {
    // A monitor that fails on the traced state may fail at its first call
    // in sicm run, on the initial state, with that state's numbers in the
    // message: called so here, it raises that error where sicm run does
    // (at the top level, the executable's failure). If it does not fail
    // there, the trace's error stands.
    if (e.cause == ErrorCause::Limit || e.cause == ErrorCause::Interrupted) throw;
    Error traced = e;
    before.restore();
    apply_procedure(monitor, &a[0], 1);
    throw traced;
  }
  // sicm run gives the monitor's first call the state as the program wrote
  // it: where that holds exact numbers (a time of 0), which print as exact,
  // the first call is the monitor traced on that state itself.
  if (has_exact_leaf(a[0])) {
    FunctionScope scope(procedure_name(monitor));
    input_like(a[0]); // the function's inputs, as every monitor's: the state
    Value x = a[0];
    apply_procedure(monitor, &x, 1);
    s.first_monitor = scope.id();
  }
  trace_events(a, n, all, a[0], s, who);
  Value r = state_result(a[0], s);
  emit(std::move(s));
  return r;
}

Value P_evolve(Value *a, int n) {
  return make_named(retrying_native<run_evolve>, sysder_of(a, n, "evolve"),
                    &g_build->evolver_lambda);
}

// ((crossings sysder . params) state event direction t-final [tolerance
// [integrator [count]]]): with every argument known at compile time the
// crossings are computed now, by sicm run's primitive (the same runtime,
// the same numbers: a list known at compile time, which prints); else a
// Crossings statement whose states go to a run-time list (which walks,
// counts and maps, but does not print, as such lists do: pe/lists.cpp).
Value crossings_in_build(NativeProc *self, Value *a, int n) {
  static const char who[] = "crossings";
  check_numeric_arguments(who, a, n, self);
  bool known = true;
  for (int i = 0; i < n; ++i)
    if (contains_dynamic(a[i])) known = false;
  if (known) return crossings_now(self, a, n);
  check_monitor_arity(here(), who, a[1]);
  RStmt s{RKind::Crossings};
  s.loc = here();
  s.number = static_number(a, n, 4, kAdvancerTolerance, who);
  s.method = method_of(a, n, 5, who);
  check_reachable_tolerance(s.loc, who, integrator_of_c_name(s.method), s.number);
  s.count = static_cast<int>(static_count(a, n, 6));
  const std::string &direction = symbol_name(a[2]);
  s.direction = direction == "up"     ? SICM_ODE_EVENT_UP
                : direction == "down" ? SICM_ODE_EVENT_DOWN
                                      : SICM_ODE_EVENT_BOTH;
  state_args(a[0], s, who);
  s.args.push_back(expr_of(a[3], who));
  trace_system(self->a, a[0], s, who);
  check_taylor(s, who);
  trace_singular_factors(a[0], s);
  trace_jacobian(self->a, a[0], s);
  s.monitor = trace_event_function(a[1], a[0], who);
  gcvec<Value> leaves;
  state_leaves(a[0], leaves);
  s.list = new_list(inexact_leaves(a[0]), std::vector<RType>(leaves.size(), RType::Real), who);
  const int list = s.list;
  emit(std::move(s));
  RStmt length{RKind::Let};
  length.compute = RCompute::ListLength;
  length.list = list;
  Value count = new_var(RType::Integer);
  length.var = var_of(count);
  current_block().push_back(std::move(length));
  return make_rtlist(list, true, false, Value::fixnum(0), count); // in push order
}

Value P_crossings(Value *a, int n) {
  return make_named(crossings_in_build, sysder_of(a, n, "crossings"), &g_build->crossings_lambda);
}

} // namespace

// What this file specializes (the table is pe/specialized.cpp).
const PrimFn
    p_definite_integral = retrying<traced_or_computed<P_definite_integral, kDefiniteIntegral>>,
    p_minimize = retrying<traced_or_computed<P_minimize<kMinimize>, kMinimize>>,
    p_brent_min = retrying<traced_or_computed<P_minimize<kBrentMin>, kBrentMin>>,
    p_multidimensional_minimize =
        retrying<traced_or_computed<P_multidimensional_minimize, kMultidimensionalMinimize>>,
    p_find_root = retrying<traced_or_computed<P_find_root, kFindRoot>>,
    p_nelder_mead = P_nelder_mead,
    p_bisect = retrying<traced_or_computed<bisect_at_run_time, kBisect>>,
    p_state_advancer = P_state_advancer, p_evolve = P_evolve, p_crossings = P_crossings;

} // namespace sicm::build
