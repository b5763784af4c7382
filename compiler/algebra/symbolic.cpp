// The bridge between Scheme values and the expression algebra, and the algebra's primitives.
#include "algebra/symbolic.hpp"

#include <cmath>
#include <cstring>

#include "algebra/structure.hpp"
#include "base/number.hpp"
#include "base/primitive.hpp"
#include "cas/expr.hpp"
#include "cas/simplify.hpp"
#include "eval/core.hpp"
#include "print/printer.hpp"
#include "sicm/runtime.h"

namespace sicm {

namespace {

// An expression id as a Value: numbers and symbols as themselves, anything
// else as Tag::Expr.
Value expr_value(ExprId id) {
  const ExprNode &n = expr_node(id);
  switch (n.kind) {
  case ExprKind::Rational:
  case ExprKind::Flonum: return expr_number_value(id);
  case ExprKind::Symbol: return Value::object(Tag::Symbol, n.sym);
  case ExprKind::Apply:
  case ExprKind::Call: break;
  }
  Value v;
  v.tag = Tag::Expr;
  v.i = id;
  return v;
}

Value datum_to_value(Value d, const char *who);

// A Value usable inside an expression as a node: a number, a symbol, an
// expression, an up/down structure (a Call of up or down), a list datum.
ExprId value_to_expr(Value v, int argpos, const char *who) {
  switch (v.tag) {
  case Tag::Expr: return static_cast<ExprId>(v.i);
  case Tag::Symbol: return expr_symbol(v.symbol());
  case Tag::Structure: {
    Structure *s = as_structure(v);
    std::vector<ExprId> items;
    for (size_t i = 0; i < s->len; i++)
      items.push_back(value_to_expr(s->items[i], argpos, who));
    ExprId head = expr_symbol(intern(s->up ? "up" : "down").symbol());
    return expr_call(head, items.data(), items.size());
  }
  case Tag::Pair: return value_to_expr(datum_to_value(v, who), argpos, who);
  default:
    if (is_number(v)) return expr_from_number(v);
    wrong_type(v, argpos, who);
  }
}

// ---- decimal constants (see DecimalConstants) -------------------------------------

thread_local int g_decimal_constants = 0;

// ---- kernel parameters (see KernelParameters) --------------------------------------

thread_local KernelParameters *g_kernel_parameters = nullptr;

// A flonum that a kernel takes as a parameter: any finite flonum but 0.
// Zero alone is folded, because it changes the kernel's structure (a term
// with a zero coefficient vanishes: an effect switched off costs nothing)
// and folding it rounds nothing. Any other value folded as a constant
// (1.5 times 2/3 made 1, 2. merged with the 1/2 of a kinetic energy) would
// round otherwise than the executable does when the same number is a
// run-time value there (a (parameter) not --fix'ed, a scan's loop
// variable), and sicm run and the executable must compute the same bits.
bool parametric_flonum(Value v) {
  return v.is(Tag::Flonum) && std::isfinite(v.d) && v.d != 0;
}

bool captured_run_time_value(Value v) {
  return !is_number(v) && g_kernel_parameters->is_captured(v);
}

// Does v depend on the kernel's inputs (a symbolic value that is not a
// captured run-time value)?
bool depends_on_inputs(Value v) {
  return !is_number(v) && !captured_run_time_value(v);
}

// The arguments of an operation with the numbers and captured run-time
// values that meet the kernel's inputs made parameters (the exponent of
// expt stays: an integer exponent is a product). Returns args itself when
// nothing changes.
const Value *parameter_arguments(Op op, const Value *args, int nargs, gcvec<Value> &storage) {
  if (!g_kernel_parameters) return args;
  bool inputs = false;
  for (int i = 0; i < nargs; i++)
    inputs = inputs || depends_on_inputs(args[i]);
  if (!inputs) return args;
  for (int i = 0; i < nargs; i++) {
    if (op == Op::Expt && i == 1) continue;
    if (!parametric_flonum(args[i]) && !captured_run_time_value(args[i])) continue;
    if (storage.empty()) storage.assign(args, args + nargs);
    storage[i] = g_kernel_parameters->parameter_for(args[i]);
  }
  return storage.empty() ? args : storage.data();
}

// The arguments of an operation, with finite flonums made decimal rationals
// when the mode is on and some argument is symbolic. Returns args itself
// when nothing changes.
const Value *decimal_arguments(const Value *args, int nargs, gcvec<Value> &storage) {
  if (g_decimal_constants == 0) return args;
  bool symbolic = false, flonum = false;
  for (int i = 0; i < nargs; i++) {
    symbolic = symbolic || !is_number(args[i]);
    flonum = flonum || (args[i].is(Tag::Flonum) && std::isfinite(args[i].d));
  }
  if (!symbolic || !flonum) return args;
  storage.assign(args, args + nargs);
  for (Value &v : storage)
    if (v.is(Tag::Flonum) && std::isfinite(v.d)) v = decimal_rational(v.d);
  return storage.data();
}

// ---- construction with light rewrites ----------------------------------------------

bool exact_zero(Value v) {
  return is_exact(v) && num_is_zero(v);
}

bool exact_one(Value v) {
  return v.is(Tag::Fixnum) && v.i == 1;
}

// Sum of numbers and expressions: numbers folded into one last term, exact
// zeros dropped.
Value build_sum(const Value *args, int n, const char *who) {
  std::vector<ExprId> terms;
  Value constant = Value::fixnum(0);
  for (int i = 0; i < n; i++) {
    if (is_number(args[i]))
      constant = num_add(constant, args[i]);
    else
      terms.push_back(value_to_expr(args[i], i + 1, who));
  }
  if (terms.empty()) return constant;
  if (!exact_zero(constant)) terms.push_back(expr_from_number(constant));
  if (terms.size() == 1) return expr_value(terms[0]);
  return expr_value(expr_apply(Op::Add, terms.data(), terms.size()));
}

// Product: numbers folded into one first factor, exact ones dropped, an exact
// zero factor makes the product 0.
Value build_product(const Value *args, int n, const char *who) {
  std::vector<ExprId> factors;
  Value coefficient = Value::fixnum(1);
  for (int i = 0; i < n; i++) {
    if (is_number(args[i]))
      coefficient = num_mul(coefficient, args[i]);
    else
      factors.push_back(value_to_expr(args[i], i + 1, who));
  }
  if (exact_zero(coefficient) || factors.empty()) return coefficient;
  if (!exact_one(coefficient)) factors.insert(factors.begin(), expr_from_number(coefficient));
  if (factors.size() == 1) return expr_value(factors[0]);
  return expr_value(expr_apply(Op::Mul, factors.data(), factors.size()));
}

Value build_power(Value base, Value exponent) {
  if (exact_zero(exponent)) return Value::fixnum(1);
  if (exact_one(exponent)) return base;
  if (exact_one(base)) return base;
  ExprId b = value_to_expr(base, 1, "expt");
  ExprId e = value_to_expr(exponent, 2, "expt");
  return expr_value(expr_apply(Op::Expt, {b, e}));
}

// The reciprocal of a value: a number's (division by an exact zero is
// MIT's error), otherwise (expt x -1).
Value reciprocal(Value v) {
  if (is_number(v)) return num_div(Value::fixnum(1), v);
  return build_power(v, Value::fixnum(-1));
}

// a / b as a quotient node, not as a product with the reciprocal of b:
// x / 3. and x * (1/3.) round differently, and the residual C of sicm build
// must divide where the interpreter divides (the simplifier reads both forms
// as the same rational function). Division by an exact zero is MIT's error,
// by an exact one is a; an exact zero divided by anything is 0.
Value build_quotient(Value a, Value b) {
  if (exact_zero(b)) return reciprocal(b); // raises
  if (exact_one(b)) return a;
  if (exact_zero(a)) return a;
  ExprId n = value_to_expr(a, 1, "/");
  ExprId d = value_to_expr(b, 2, "/");
  return expr_value(expr_apply(Op::Div, {n, d}));
}

Value fold_unary(Op op, Value x) {
  switch (op) {
  case Op::Sqrt: return num_sqrt(x);
  case Op::Exp: return num_exp(x);
  case Op::Log: return num_log(x);
  case Op::Sin: return num_sin(x);
  case Op::Cos: return num_cos(x);
  case Op::Tan: return num_tan(x);
  case Op::Asin: return num_asin(x);
  case Op::Acos: return num_acos(x);
  case Op::Atan: return num_atan(x);
  case Op::Abs: return num_abs(x);
  case Op::Sinh: return exact_zero(x) ? Value::fixnum(0) : Value::flonum(std::sinh(to_double(x)));
  case Op::Cosh: return exact_zero(x) ? Value::fixnum(1) : Value::flonum(std::cosh(to_double(x)));
  default: SICM_ASSERT(false);
  }
  return x;
}

} // namespace

// Digits d1...dn and exponent e denote d1.d2...dn * 10^e.
Value decimal_rational(double d) {
  if (d == 0) return Value::fixnum(0);
  char digits[32];
  int e10 = 0;
  size_t n = sicm_shortest_digits(digits, &e10, d);
  digits[n] = '\0';
  mpq_t q;
  mpq_init(q);
  mpz_set_str(mpq_numref(q), digits, 10);
  int scale = e10 - static_cast<int>(n - 1); // value = digits * 10^scale
  mpz_t p;
  mpz_init(p);
  mpz_ui_pow_ui(p, 10, static_cast<unsigned long>(scale < 0 ? -scale : scale));
  if (scale < 0)
    mpz_set(mpq_denref(q), p);
  else
    mpz_mul(mpq_numref(q), mpq_numref(q), p);
  mpz_clear(p);
  if (d < 0) mpz_neg(mpq_numref(q), mpq_numref(q));
  Value v = make_rational(q);
  mpq_clear(q);
  return v;
}

DecimalConstants::DecimalConstants() {
  ++g_decimal_constants;
}

DecimalConstants::~DecimalConstants() {
  --g_decimal_constants;
}

KernelParameters::KernelParameters(CapturedTest is_captured)
    : is_captured_(is_captured), outer_(g_kernel_parameters) {
  g_kernel_parameters = this;
}

KernelParameters::~KernelParameters() {
  g_kernel_parameters = outer_;
}

Value KernelParameters::parameter_for(Value v) {
  // Equal flonums are one parameter; a run-time value is one by its expression.
  size_t next = values.size(), j;
  if (v.is(Tag::Flonum)) {
    uint64_t bits;
    std::memcpy(&bits, &v.d, sizeof bits);
    j = by_bits_.emplace(bits, next).first->second;
  } else {
    j = by_expression_.emplace(value_to_expr(v, 1, "kernel"), next).first->second;
  }
  if (j < next) return Value::object(Tag::Symbol, symbols[j]);
  Value sym = make_uninterned_symbol("k" + std::to_string(values.size()));
  values.push_back(v);
  symbols.push_back(sym.symbol());
  return sym;
}

Value symbolic_apply(Op op, const Value *raw_args, int nargs) {
  gcvec<Value> parametric, decimal;
  const Value *args =
      decimal_arguments(parameter_arguments(op, raw_args, nargs, parametric), nargs, decimal);
  const char *who = op_info(op).scheme_name;
  int arity = op_info(op).arity;
  bool n_ary = op == Op::Add || op == Op::Mul || op == Op::Sub || op == Op::Div;
  SICM_ASSERT(n_ary ? nargs >= (op == Op::Sub || op == Op::Div)
                    : nargs == arity || (op == Op::Atan && (nargs == 1 || nargs == 2)));
  switch (op) {
  case Op::Add: return build_sum(args, nargs, who);
  case Op::Mul: return build_product(args, nargs, who);
  case Op::Sub: {
    if (nargs == 1) {
      Value v[2] = {Value::fixnum(-1), args[0]};
      return build_product(v, 2, who);
    }
    gcvec<Value> terms{args[0]};
    for (int i = 1; i < nargs; i++) {
      Value v[2] = {Value::fixnum(-1), args[i]};
      terms.push_back(build_product(v, 2, who));
    }
    return build_sum(terms.data(), static_cast<int>(terms.size()), who);
  }
  case Op::Div: {
    if (nargs == 1) return build_quotient(Value::fixnum(1), args[0]);
    Value q = args[0];
    for (int i = 1; i < nargs; i++)
      q = build_quotient(q, args[i]);
    return q;
  }
  case Op::Expt:
    if (is_number(args[0]) && is_number(args[1])) return num_expt(args[0], args[1]);
    return build_power(args[0], args[1]);
  default: break;
  }
  bool numbers = true;
  for (int i = 0; i < nargs; i++)
    numbers = numbers && is_number(args[i]);
  if (numbers) return nargs == 2 ? num_atan2(args[0], args[1]) : fold_unary(op, args[0]);
  ExprId ids[2];
  for (int i = 0; i < nargs; i++)
    ids[i] = value_to_expr(args[i], i + 1, who);
  return expr_value(expr_apply(op, ids, static_cast<size_t>(nargs)));
}

Value symbolic_call(Value head, const Value *args, int nargs) {
  ExprId h = value_to_expr(head, 1, "apply");
  std::vector<ExprId> ids;
  for (int i = 0; i < nargs; i++)
    ids.push_back(value_to_expr(args[i], i + 2, "apply"));
  return expr_value(expr_call(h, ids.data(), ids.size()));
}

namespace {

// A prefix-form datum as a value: (op args...) for operators of ops.def with a
// fitting number of arguments (built as by arithmetic), any other list as a
// function applied to arguments, (up ...) and (down ...) included.
Value datum_to_value(Value d, const char *who) {
  if (!is_pair(d)) {
    if (is_number(d) || is_symbol(d) || d.is(Tag::Expr)) return d;
    wrong_type(d, 1, who);
  }
  long len = list_length(d);
  if (len < 1) wrong_type(d, 1, who);
  gcvec<Value> args;
  for (Value p = cdr(d); is_pair(p); p = cdr(p))
    args.push_back(datum_to_value(car(p), who));
  int n = static_cast<int>(args.size());
  Value head = car(d);
  if (is_symbol(head)) {
    size_t nops = 0;
    const OpInfo *ops = op_table(&nops);
    for (size_t i = 0; i < nops; i++) {
      Op op = static_cast<Op>(i);
      if (symbol_name(head) != ops[i].scheme_name) continue;
      int arity = ops[i].arity;
      bool fits = op == Op::Atan ? n == 1 || n == 2 : arity < 0 ? n >= 1 : n == arity;
      if (fits) return symbolic_apply(op, args.data(), n);
    }
  }
  return symbolic_call(datum_to_value(head, who), args.data(), n);
}

} // namespace

Value datum_to_expression(Value datum) {
  return datum_to_value(datum, "datum->expression");
}

Value simplify_value(Value v) {
  switch (v.tag) {
  case Tag::Expr: return expr_value(simplify_expr(static_cast<ExprId>(v.i)));
  case Tag::Pair: {
    if (list_length(v) < 0) return v;
    gcvec<Value> items;
    for (Value p = v; is_pair(p); p = cdr(p))
      items.push_back(simplify_value(car(p)));
    return list_from(items.data(), items.size());
  }
  default: return v;
  }
}

Value expression_to_datum(Value v) {
  switch (v.tag) {
  case Tag::Expr: return expr_to_datum(simplify_expr(static_cast<ExprId>(v.i)));
  case Tag::Pair: {
    if (list_length(v) < 0) return v;
    gcvec<Value> items;
    for (Value p = v; is_pair(p); p = cdr(p))
      items.push_back(expression_to_datum(car(p)));
    return list_from(items.data(), items.size());
  }
  default: return v;
  }
}

// ---- primitives ---------------------------------------------------------------------

namespace {

Value P_simplify(Value *a, int) {
  return simplify_value(a[0]);
}

// print-expression and pe write the simplified form on one line: the book's
// results are read and compared line by line (pp breaks long forms).
Value P_print_expression(Value *a, int) {
  output(write_string(simplify_value(a[0])));
  output("\n");
  return Value::unspecified();
}

Value P_expression(Value *a, int) {
  return expression_to_datum(a[0]);
}

Value P_datum_to_expression(Value *a, int) {
  return datum_to_expression(a[0]);
}

} // namespace

void install_algebra_primitives() {
  define_primitive("simplify", 1, 1, Stage::Pure, P_simplify);
  define_primitive("print-expression", 1, 1, Stage::Effect, P_print_expression);
  define_primitive("pe", 1, 1, Stage::Effect, P_print_expression);
  define_primitive("expression", 1, 1, Stage::Pure, P_expression);
  define_primitive("datum->expression", 1, 1, Stage::Pure, P_datum_to_expression);
  set_datum_converter(Tag::Expr, expression_to_datum);
}

} // namespace sicm
