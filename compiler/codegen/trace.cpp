// Tracing a procedure into expressions over fresh input symbols (see trace.hpp).
//
// The procedure runs once, in the ordinary evaluator, on arguments whose
// scalar leaves are uninterned symbols: generic arithmetic then builds
// expressions instead of numbers. Whatever the procedure does with the
// numbers it closes over is done at trace time, so known parameters fold into
// constants and terms multiplied by an exact zero vanish. What comes back is
// checked leaf by leaf: a leaf must simplify to a number or to an expression
// whose only symbols are the inputs and whose only operations are those of
// ops.def (the C emitter knows no others).
#include "codegen/trace.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "algebra/linear_solve.hpp"
#include "algebra/structure.hpp"
#include "algebra/symbolic.hpp"
#include "base/number.hpp"
#include "base/primitive.hpp"
#include "codegen/emit_c.hpp"
#include "codegen/emit_taylor.hpp"
#include "codegen/jit.hpp"
#include "codegen/kernel.hpp"
#include "codegen/kernel_form.hpp"
#include "codegen/kernel_interpreter.hpp"
#include "codegen/singular_factors.hpp"
#include "codegen/state_shape.hpp"
#include "eval/effect_guard.hpp"
#include "eval/procedure.hpp"
#include "print/printer.hpp"

namespace sicm {

// compile_kernel runs the kernel once at the sample arguments and requires
// each output to agree with the interpreter's to this relative tolerance
// (relative to max(1, |values|)): far above the rounding differences of a
// simplified expression, far below what a branch traced the wrong way gives.
constexpr double kSampleTolerance = 1e-9;

namespace {

const char *ordinal(size_t i) {
  static const char *const names[] = {"first", "second",  "third",  "fourth", "fifth",
                                      "sixth", "seventh", "eighth", "ninth",  "tenth"};
  return i < 10 ? names[i] : "a later";
}

// Messages quote user values; keep them to one readable line.
std::string brief(Value v) {
  std::string s = write_string(v);
  constexpr size_t kMax = 80;
  if (s.size() > kMax) s = s.substr(0, kMax) + "...";
  return s;
}

// Check that every node under `root` is a number, an input symbol, an
// Apply or a solve node; `seen` is shared across the leaves so each node is
// visited once.
bool check_expression(ExprId root, const std::unordered_set<Symbol *> &inputs,
                      std::unordered_set<ExprId> &seen, std::string *why_not) {
  std::vector<ExprId> stack{root};
  while (!stack.empty()) {
    ExprId id = stack.back();
    stack.pop_back();
    if (!seen.insert(id).second) continue;
    const ExprNode &n = expr_node(id);
    switch (n.kind) {
    case ExprKind::Rational:
    case ExprKind::Flonum: break;
    case ExprKind::Symbol:
      if (!inputs.count(n.sym)) {
        RunTimeValueTest run_time = run_time_value_test(); // sicm build's values
        if (run_time && run_time(Value::object(Tag::Symbol, n.sym)))
          *why_not = "the result depends on a value known only when the built program runs "
                     "(a numerical result, a parameter, a clock)";
        else
          *why_not = "the result depends on the symbol " + n.sym->name +
                     ", which is not an argument (give it a numeric value)";
        return false;
      }
      break;
    case ExprKind::Call:
      if (!is_solve_node(id)) {
        *why_not = "the result applies the unknown function " + expr_debug_string(n.head) +
                   " (a literal function cannot be compiled)";
        return false;
      }
      [[fallthrough]];
    case ExprKind::Apply: {
      const ExprId *args = expr_args(id);
      stack.insert(stack.end(), args, args + n.nargs);
      break;
    }
    }
  }
  return true;
}

// Turn the result's leaves into checked kernel outputs (kernel_form.hpp
// chooses their form).
bool collect_outputs(Value result, Trace *t, std::string *why_not) {
  gcvec<Value> leaves;
  if (is_structure(result)) {
    structure_leaves(result, leaves);
    gcvec<Value> zeros(leaves.size(), Value::fixnum(0));
    t->result_shape = shape_from_leaves(result, false, zeros.data());
  } else {
    leaves.push_back(result);
    t->result_shape = Value::fixnum(0);
  }
  for (Value leaf : leaves) {
    if (leaf_expr(leaf) != kNoExpr) continue;
    *why_not = is_structure(result)
                   ? "the result has a component that is not a number: " + brief(leaf)
                   : "the result is not a number or a structure of numbers: " + brief(result);
    return false;
  }
  std::unordered_set<Symbol *> inputs(t->inputs.begin(), t->inputs.end());
  inputs.insert(t->param_symbols.begin(), t->param_symbols.end());
  auto allowed = [&](ExprId id) {
    ExprKind kind = expr_kind(id);
    if (kind == ExprKind::Symbol) return inputs.count(expr_node(id).sym) > 0;
    return kind != ExprKind::Call || is_solve_node(id);
  };
  t->outputs = kernel_outputs(leaves, allowed);
  std::unordered_set<ExprId> seen;
  for (ExprId id : t->outputs)
    if (!check_expression(id, inputs, seen, why_not)) return false;
  return true;
}

} // namespace

bool is_numeric_shape(Value v) {
  if (is_number(v)) return true;
  if (!is_structure(v)) return false;
  Structure *s = as_structure(v);
  for (size_t i = 0; i < s->len; ++i)
    if (!is_numeric_shape(s->items[i])) return false;
  return true;
}

Value apply_traced(Value proc, gcvec<Value> args) {
  DecimalConstants decimal; // 9.8 means 49/5 in the kernel's algebra
  KernelTracing tracing;    // a matrix of run-time values is solved, not inverted
  return apply_procedure(proc, args.data(), static_cast<int>(args.size()));
}

// An error's text with the trace's names for the arguments' leaves (x0,
// x1, ..., which the user never wrote) replaced by where each leaf is:
// <the first argument>, <(ref (the second argument) 1 0)>.
static std::string in_users_terms(std::string text, const gcvec<Value> &samples, const Trace &t) {
  std::vector<std::pair<std::string, std::string>> names; // trace name -> description
  size_t k = 0;
  for (size_t i = 0; i < samples.size(); ++i) {
    std::string arg = std::string("the ") + ordinal(i) + " argument";
    std::vector<std::string> paths = state_leaf_paths(samples[i], "(" + arg + ")");
    for (const std::string &path : paths)
      if (k < t.inputs.size())
        names.emplace_back(t.inputs[k++]->name, paths.size() == 1 && is_number(samples[i])
                                                    ? "<" + arg + ">"
                                                    : "<" + path + ">");
  }
  // Longest names first: x10 before x1.
  std::sort(names.begin(), names.end(),
            [](const auto &a, const auto &b) { return a.first.size() > b.first.size(); });
  auto word_char = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (const auto &[name, description] : names) {
    for (const std::string &form : {"\u00ab" + name + "\u00bb", name}) {
      for (size_t at = text.find(form); at != std::string::npos; at = text.find(form, at)) {
        bool whole = (at == 0 || !word_char(text[at - 1])) &&
                     (at + form.size() >= text.size() || !word_char(text[at + form.size()]));
        if (!whole) {
          at += form.size();
          continue;
        }
        text.replace(at, form.size(), description);
        at += description.size();
      }
    }
  }
  return text;
}

bool trace_procedure(Value proc, Value sample_args, Trace *t, std::string *why_not) {
  if (!is_procedure(proc)) {
    *why_not = "the object " + brief(proc) + " is not a procedure";
    return false;
  }
  if (list_length(sample_args) < 0) {
    *why_not = "the sample arguments are not a list";
    return false;
  }
  gcvec<Value> samples = list_to_vector(sample_args);
  gcvec<Value> args;
  for (size_t i = 0; i < samples.size(); ++i) {
    if (!is_numeric_shape(samples[i])) {
      *why_not = std::string("the ") + ordinal(i) + " sample argument, " + brief(samples[i]) +
                 ", is not a number or a structure of numbers";
      return false;
    }
    // The sample with fresh symbols x0, x1, ... for its leaves, as sicm
    // build gives a traced procedure residual variables (input_like).
    gcvec<Value> leaves;
    state_leaves(samples[i], leaves);
    for (Value &leaf : leaves) {
      leaf = make_uninterned_symbol("x" + std::to_string(t->inputs.size()));
      t->inputs.push_back(leaf.symbol());
    }
    args.push_back(state_from_leaves(samples[i], leaves));
  }
  try {
    // The kernel runs without the interpreter, even in sicm build
    // (compile-procedure), so no effect may happen only while tracing.
    EffectGuard effects;
    Value result;
    {
      KernelParameters params;
      result = apply_traced(proc, args);
      t->param_symbols = params.symbols;
      t->params = params.values;
    }
    return collect_outputs(result, t, why_not);
  } catch (const Error &e) {
    *why_not = std::string("applying it to symbolic arguments failed: ") +
               in_users_terms(e.what(), samples, *t);
    return false;
  }
}

// ---- the pipeline: trace, emit, compile, check -------------------------------------

namespace {

void finalize_kernel(void *obj, void *) {
  static_cast<Kernel *>(obj)->~Kernel();
}

std::string procedure_name(Value proc) {
  if (proc.is(Tag::Closure) && proc.as<Closure>()->lambda->name)
    return proc.as<Closure>()->lambda->name->name;
  if (proc.is(Tag::Primitive)) return proc.as<Primitive>()->name;
  return "anonymous";
}

bool close_enough(double a, double b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  if (a == b) return true;
  return std::fabs(a - b) <= kSampleTolerance * std::max({1.0, std::fabs(a), std::fabs(b)});
}

std::string show_double(double d) {
  return write_string(Value::flonum(d));
}

// Run the kernel and the interpreter at the sample arguments and compare.
// A procedure that raises there (a division by zero at 0.) is not compared.
bool agrees_at_sample(const Kernel *k, Value proc, Value sample_args, std::string *why_not) {
  gcvec<Value> samples = list_to_vector(sample_args);
  Value expected;
  try {
    expected = apply_procedure(proc, samples.data(), static_cast<int>(samples.size()));
  } catch (const Error &) {
    return true;
  }
  if (!value_has_shape(expected, k->result_shape)) {
    *why_not = "at the sample arguments the procedure returns " + brief(expected) +
               ", which is not shaped like the traced result (does it branch on its arguments?)";
    return false;
  }
  std::vector<double> in, want, got(k->nout);
  for (Value s : samples)
    flatten_value(s, in);
  flatten_value(expected, want);
  kernel_call(k, in.data(), got.data());
  for (size_t j = 0; j < k->nout; ++j) {
    if (close_enough(got[j], want[j])) continue;
    *why_not = "at the sample arguments the compiled kernel gives " + show_double(got[j]) +
               " for output " + std::to_string(j) + " but the procedure gives " +
               show_double(want[j]) + " (does it branch on = or zero? of an argument?)";
    return false;
  }
  return true;
}

} // namespace

namespace {
KernelListener g_kernel_listener = nullptr;
} // namespace

void set_kernel_listener(KernelListener listener) {
  g_kernel_listener = listener;
}

Kernel *compile_kernel(Value proc, Value sample_args, const char *name, std::string *why_not,
                       KernelOptions options) {
  std::string ignored;
  if (!why_not) why_not = &ignored;
  std::string kname = name ? name : procedure_name(proc);
  JitRequest request(user_call_loc()); // before the trace moves the evaluator into proc
  Trace t;
  if (!trace_procedure(proc, sample_args, &t, why_not)) return nullptr;
  std::string c_name = c_kernel_name(kname);
  std::string source = emit_kernel_unit(t, c_name, kname);
  SingularFactors factors;
  std::string probe_name = c_name + "_singular_factors";
  if (options.probe_singularities && list_length(sample_args) == 1) {
    std::vector<std::string> paths = state_leaf_paths(car(sample_args), "state");
    std::unordered_map<Symbol *, std::string> names;
    for (size_t i = 0; i < t.inputs.size() && i < paths.size(); ++i)
      names[t.inputs[i]] = paths[i];
    std::unordered_map<ExprId, ExprId> values; // the parameters' values folded in again
    for (size_t j = 0; j < t.param_symbols.size(); ++j)
      values[expr_symbol(t.param_symbols[j])] =
          expr_from_number(decimal_rational(to_double(t.params[j])));
    factors = singular_factors(with_leaves(t.outputs, values), [&](Symbol *s) {
      auto it = names.find(s);
      return it == names.end() ? std::string() : it->second;
    });
    if (!factors.values.empty()) {
      Trace probe{t.inputs, factors.values, Value::fixnum(0), {}, {}};
      source += "\nvoid " + probe_name + "(const double *in, double *out, const double *p);\n\n";
      source += emit_kernel_function(probe, probe_name, false);
    }
  }
  // The Taylor coefficients in both precisions (taylor, taylor-extended).
  std::string taylor_name = c_name + "_taylor", taylor_why_not;
  std::string extended_name = c_name + "_taylor_extended";
  bool has_taylor = false;
  if (options.taylor && list_length(sample_args) != 1)
    taylor_why_not = "it is not a system derivative (a procedure of one state)";
  if (options.taylor && list_length(sample_args) == 1) {
    std::string taylor = emit_taylor_function(t, taylor_name, &taylor_why_not);
    std::string extended =
        emit_taylor_function(t, extended_name, &taylor_why_not, TaylorPrecision::Extended);
    has_taylor = !taylor.empty() && !extended.empty();
    if (has_taylor)
      source += "\n" + c_taylor_support() + c_taylor_support(TaylorPrecision::Extended) + "void " +
                taylor_name + "(const double *in, int order, double *c, const double *p);\n" +
                "void " + extended_name +
                "(const long double *in, int order, long double *c, const double *p);\n\n" +
                taylor + "\n" + extended;
  }
  std::string so;
  void *fn = nullptr, *probe_fn = nullptr, *taylor_fn = nullptr, *extended_fn = nullptr;
  std::shared_ptr<InterpretedKernel> interpreted;
  if (kernels_interpreted()) {
    // The same schedules the C above prints, run by the kernel interpreter.
    interpreted = std::make_shared<InterpretedKernel>();
    interpreted->fn = load_kernel_program(t.outputs, t.inputs, t.param_symbols);
    if (!factors.values.empty())
      interpreted->singular_factors = load_kernel_program(factors.values, t.inputs, {});
    for (Value v : t.params)
      interpreted->params.push_back(to_double(v));
    // The kernel interpreter runs the derivative, not Taylor recurrences:
    // a taylor method's coefficients are compiled C even so, the C sicm
    // build compiles, so the integration gives the same bits.
    if (has_taylor) {
      std::string why;
      taylor_fn = jit_load(source, taylor_name, &so, &why);
      extended_fn = taylor_fn ? jit_load(source, extended_name, &so, &why) : nullptr;
      if (!taylor_fn || !extended_fn) {
        taylor_fn = extended_fn = nullptr;
        taylor_why_not = "no Taylor coefficients: " + why;
      }
    }
  } else {
    fn = jit_load(source, c_name, &so, why_not);
    if (!fn) return nullptr;
    probe_fn = factors.values.empty() ? nullptr : jit_load(source, probe_name, &so, why_not);
    taylor_fn = has_taylor ? jit_load(source, taylor_name, &so, why_not) : nullptr;
    extended_fn = has_taylor ? jit_load(source, extended_name, &so, why_not) : nullptr;
  }
  Kernel *k = gc_new<Kernel>();
  // ignore_self: a std::string member may point into the object (its short-string buffer).
  GC_register_finalizer_ignore_self(k, finalize_kernel, nullptr, nullptr, nullptr);
  k->fn = interpreted ? interpreted_kernel_entry() : reinterpret_cast<KernelFn>(fn);
  k->nin = t.inputs.size();
  k->nout = t.outputs.size();
  k->arg_shapes = sample_args;
  k->source = proc;
  k->result_shape = t.result_shape;
  k->name = kname;
  k->c_name = c_name;
  k->c_source = std::move(source);
  k->so_path = so;
  k->singular_factors = reinterpret_cast<KernelFn>(probe_fn);
  if (interpreted && interpreted->singular_factors) k->singular_factors = interpreted_probe_entry();
  if (k->singular_factors) k->singular_texts = std::move(factors.texts);
  k->taylor = reinterpret_cast<TaylorFn>(taylor_fn);
  k->taylor_extended = reinterpret_cast<TaylorExtendedFn>(extended_fn);
  k->taylor_why_not = std::move(taylor_why_not);
  for (Value v : t.params)
    k->params.push_back(to_double(v));
  k->interpreted = std::move(interpreted);
  if (!agrees_at_sample(k, proc, sample_args, why_not)) return nullptr;
  if (g_kernel_listener) g_kernel_listener(k);
  return k;
}

void kernel_call(const Kernel *k, const double *in, double *out) {
  k->fn(in, out, kernel_params(k));
}

Value kernel_result_value(const Kernel *k, const double *out) {
  if (!is_structure(k->result_shape)) return Value::flonum(out[0]);
  gcvec<Value> leaves(k->nout);
  for (size_t j = 0; j < k->nout; ++j)
    leaves[j] = Value::flonum(out[j]);
  return shape_from_leaves(k->result_shape, false, leaves.data());
}

void flatten_value(Value v, std::vector<double> &out, const char *who) {
  if (is_number(v)) {
    out.push_back(to_double(v));
    return;
  }
  if (!is_structure(v)) wrong_type(v, 1, who);
  Structure *s = as_structure(v);
  for (size_t i = 0; i < s->len; ++i)
    flatten_value(s->items[i], out, who);
}

bool value_has_shape(Value v, Value shape) {
  if (!is_structure(shape)) return is_number(v);
  if (!is_structure(v)) return false;
  Structure *a = as_structure(v), *b = as_structure(shape);
  if (a->up != b->up || a->len != b->len) return false;
  for (size_t i = 0; i < a->len; ++i)
    if (!value_has_shape(a->items[i], b->items[i])) return false;
  return true;
}

} // namespace sicm
