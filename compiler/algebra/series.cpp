// Lazy power series: each series knows how to compute its k-th term from
// its operands, and remembers the terms it has computed.
//
// A series of functions (such as ((exp (* 'epsilon D)) f), the Taylor series
// of f) applies to arguments termwise, giving a series of values. Sums and
// scalar multiples work termwise, products by the Cauchy rule, all lazily,
// so an infinite series costs only the terms someone asks for.
#include "algebra/series.hpp"

#include "algebra/generic.hpp"
#include "algebra/operator.hpp"
#include "base/number.hpp"
#include "base/primitive.hpp"
#include "eval/core.hpp"
#include "eval/procedure.hpp"
#include "print/printer.hpp"

namespace sicm {

namespace {

enum class SeriesKind {
  Exp,         // a: operator x, b: function f; powers: x^k f
  ExpOfSeries, // a: operator x, b: series h (of functions); powers: the Exp series of x and
               // h_j; term n is the sum over k + j = n of x^k h_j / k!
  Applied,     // a: series of functions, b: argument list
  Sum,         // a + b
  Scale,       // coefficient a times series b
  Product,     // Cauchy product of a and b
  Quotient,    // a / b: the series c with c b = a, term by term (b's first term not zero)
  Given,       // the terms listed, then zeros
  Derivative,  // d/dt of series a: term k is (k + 1) a_{k+1}
  Integral,    // the series whose term 0 is a and whose derivative is series b
  Power,       // series a to the power b (not a series): (a^b)' = b a' a^(b-1), the series
               // a^(b-1) made when first needed (in powers[0]), and so on down, so that the
               // terms are those of repeated differentiation and print as they do
};

struct Series {
  SeriesKind kind;
  Value a, b;
  gcvec<Value> terms;  // computed so far
  gcvec<Value> powers; // Exp: x^k f for k < powers.size()
};

Value series_apply(void *obj, Value *args, int nargs);
void write_series(std::string &out, const void *, bool) {
  out += "#[series]";
}
const OpaqueKind kSeriesKind = {"series", write_series, series_apply};

Series *as_series(Value v) {
  return static_cast<Series *>(v.as<Opaque>()->obj);
}

Value make_series(SeriesKind kind, Value a, Value b) {
  Series *s = gc_new<Series>();
  s->kind = kind;
  s->a = a;
  s->b = b;
  return Value::object(Tag::Opaque, gc_new<Opaque>(Opaque{&kSeriesKind, s}));
}

Value factorial(size_t k) {
  Value f = Value::fixnum(1);
  for (size_t i = 2; i <= k; ++i)
    f = num_mul(f, Value::fixnum(static_cast<int64_t>(i)));
  return f;
}

Value compute_term(Series *s, size_t k) {
  switch (s->kind) {
  case SeriesKind::Exp: {
    while (s->powers.size() <= k)
      s->powers.push_back(s->powers.empty() ? s->b : apply_operator(s->a, s->powers.back()));
    return g_mul(num_div(Value::fixnum(1), factorial(k)), s->powers[k]);
  }
  case SeriesKind::ExpOfSeries: {
    // exp(x) h = sum_k x^k/k! sum_j h_j, collected by total order: the order
    // of a term of h (a power of epsilon in the book's H-pendulum-series)
    // plus that of the operator's power (epsilon L_W), as scmutils collects it.
    // A zero term of h (the series' padding) contributes nothing at any order.
    while (s->powers.size() <= k) {
      Value h = series_term(s->b, s->powers.size());
      s->powers.push_back(is_exact_zero(h) ? h : make_series(SeriesKind::Exp, s->a, h));
    }
    Value sum = Value::fixnum(0);
    for (size_t j = 0; j <= k; ++j)
      if (!is_exact_zero(s->powers[j])) sum = g_add(sum, series_term(s->powers[j], k - j));
    return sum;
  }
  case SeriesKind::Applied: {
    gcvec<Value> args = list_to_vector(s->b);
    Value f = series_term(s->a, k);
    if (is_procedure(f)) return apply_procedure(f, args.data(), static_cast<int>(args.size()));
    return f; // a constant term applies as itself
  }
  case SeriesKind::Sum: return g_add(series_term(s->a, k), series_term(s->b, k));
  case SeriesKind::Scale: return g_mul(s->a, series_term(s->b, k));
  case SeriesKind::Product: {
    Value sum = Value::fixnum(0);
    for (size_t i = 0; i <= k; ++i)
      sum = g_add(sum, g_mul(series_term(s->a, i), series_term(s->b, k - i)));
    return sum;
  }
  case SeriesKind::Quotient: {
    // a_k = sum_{i <= k} b_i c_{k-i}, so c_k = (a_k - sum_{1 <= i <= k} b_i c_{k-i}) / b_0.
    Value b0 = series_term(s->b, 0);
    if (is_exact_zero(b0))
      runtime_error(current_call_loc(), "Division by zero signalled by /: a series whose first "
                                        "term is 0 has no series inverse");
    Value rest = series_term(s->a, k);
    for (size_t i = 1; i <= k; ++i)
      rest = g_sub(rest, g_mul(series_term(s->b, i), s->terms[k - i]));
    return g_div(rest, b0);
  }
  case SeriesKind::Derivative:
    return g_mul(Value::fixnum(static_cast<int64_t>(k + 1)), series_term(s->a, k + 1));
  case SeriesKind::Integral:
    if (k == 0) return s->a;
    return g_div(series_term(s->b, k - 1), Value::fixnum(static_cast<int64_t>(k)));
  case SeriesKind::Power: {
    if (k == 0) return g_binary(BinaryOp::Expt, series_term(s->a, 0), s->b);
    if (s->powers.empty()) {
      Value da = make_series(SeriesKind::Derivative, s->a, Value());
      Value lower = make_series(SeriesKind::Power, s->a, g_sub(s->b, Value::fixnum(1)));
      s->powers.push_back(g_mul(s->b, g_mul(da, lower)));
    }
    return g_div(series_term(s->powers[0], k - 1), Value::fixnum(static_cast<int64_t>(k)));
  }
  case SeriesKind::Given: {
    long n = list_length(s->a);
    if (static_cast<long>(k) >= n) return Value::fixnum(0);
    Value p = s->a;
    for (size_t i = 0; i < k; ++i)
      p = cdr(p);
    return car(p);
  }
  }
  internal_failure(__FILE__, __LINE__, "unknown series kind");
}

Value constant_series(Value x) {
  return make_series(SeriesKind::Given, list({x}), Value());
}

// ((exp (* c D)) f) at x is f(x + c t) as a power series in t: when f
// computes with arithmetic and elementary functions, it can be given the
// series x + c t itself, and every term then costs a few convolutions (the
// recurrences below), where differentiating k times nests k differentials
// (the 20th term of ((exp (* 1/2 D)) sin) took seconds). Anything else (a
// literal function, an operation a series does not take, a value that is
// not a series) is left to the series of derivatives: unspecified here.
Value taylor_by_substitution(Series *s, Value x) {
  Value c;
  if (s->kind != SeriesKind::Exp || !is_derivative_multiple(s->a, &c)) return Value();
  if (!is_number(x) && !x.is(Tag::Symbol) && !x.is(Tag::Expr)) return Value();
  Value shifted = make_series(SeriesKind::Given, list({x, c}), Value());
  try {
    Value r = apply_procedure(s->b, &shifted, 1);
    if (is_series(r)) return r;
  } catch (const Error &) {
  }
  return Value();
}

Value series_apply(void *obj, Value *args, int nargs) {
  if (nargs == 1) {
    Value r = taylor_by_substitution(static_cast<Series *>(obj), args[0]);
    if (is_series(r)) return r;
  }
  Value self = Value::object(Tag::Opaque, gc_new<Opaque>(Opaque{&kSeriesKind, obj}));
  return make_series(SeriesKind::Applied, self, list_from(args, static_cast<size_t>(nargs)));
}

// The series whose term 0 is c and whose derivative is derivative_of(it):
// the derivative may refer to the series itself (e' = a' e), since its term
// k - 1 needs only the series' terms before k.
template <typename F> Value integral_series(Value c, F derivative_of) {
  Value s = make_series(SeriesKind::Integral, c, Value());
  Value d = derivative_of(s);
  as_series(s)->b = d;
  return s;
}

// Elementary functions of a series a, from its first term and its
// derivative a' (each satisfies a first-order equation in a'); unspecified
// for the others.
Value series_function(UnaryOp op, Value a) {
  Value a0 = series_term(a, 0);
  Value da = make_series(SeriesKind::Derivative, a, Value());
  Value one = Value::fixnum(1);
  auto root_of_one_minus_square = [&] { return g_unary(UnaryOp::Sqrt, g_sub(one, g_mul(a, a))); };
  switch (op) {
  case UnaryOp::Exp: return integral_series(g_unary(op, a0), [&](Value e) { return g_mul(da, e); });
  case UnaryOp::Log: return integral_series(g_unary(op, a0), [&](Value) { return g_div(da, a); });
  case UnaryOp::Sqrt:
    return integral_series(g_unary(op, a0),
                           [&](Value r) { return g_div(da, g_mul(Value::fixnum(2), r)); });
  case UnaryOp::Sin:
  case UnaryOp::Cos: {
    Value sin = make_series(SeriesKind::Integral, g_unary(UnaryOp::Sin, a0), Value());
    Value cos = make_series(SeriesKind::Integral, g_unary(UnaryOp::Cos, a0), Value());
    as_series(sin)->b = g_mul(da, cos);
    as_series(cos)->b = g_neg(g_mul(da, sin));
    return op == UnaryOp::Sin ? sin : cos;
  }
  case UnaryOp::Tan: { // tan' = 1 / cos^2, as D writes it
    Value cos = series_function(UnaryOp::Cos, a);
    return integral_series(g_unary(op, a0), [&](Value) { return g_div(da, g_mul(cos, cos)); });
  }
  case UnaryOp::Atan:
    return integral_series(g_unary(op, a0),
                           [&](Value) { return g_div(da, g_add(one, g_mul(a, a))); });
  case UnaryOp::Asin:
    return integral_series(g_unary(op, a0),
                           [&](Value) { return g_div(da, root_of_one_minus_square()); });
  case UnaryOp::Acos:
    return integral_series(g_unary(op, a0),
                           [&](Value) { return g_neg(g_div(da, root_of_one_minus_square())); });
  case UnaryOp::Square: return g_mul(a, a);
  case UnaryOp::Cube: return g_mul(a, g_mul(a, a));
  default: return Value();
  }
}

// a^p with a or p a series: products for a natural power, the Power series
// for another power p, exp(p log a) for a series p.
Value series_expt(Value a, Value p) {
  if (is_series(a) && p.is(Tag::Fixnum) && p.i >= 0) {
    Value result = constant_series(Value::fixnum(1)), base = a;
    for (int64_t n = p.i; n > 0; n >>= 1) {
      if (n & 1) result = g_mul(result, base);
      if (n > 1) base = g_mul(base, base);
    }
    return result;
  }
  if (is_series(a) && !is_series(p)) return make_series(SeriesKind::Power, a, p);
  return g_unary(UnaryOp::Exp, g_mul(p, g_unary(UnaryOp::Log, a)));
}

Value series_unary(UnaryOp op, Value x) {
  if (op == UnaryOp::Neg) return make_series(SeriesKind::Scale, Value::fixnum(-1), x);
  if (op == UnaryOp::Invert)
    return make_series(SeriesKind::Quotient, constant_series(Value::fixnum(1)), x);
  Value f = series_function(op, x);
  if (is_series(f)) return f;
  arith_wrong_type(op, x);
}

Value series_binary(BinaryOp op, Value a, Value b) {
  bool sa = is_series(a), sb = is_series(b);
  switch (op) {
  case BinaryOp::Add:
    return make_series(SeriesKind::Sum, sa ? a : make_series(SeriesKind::Given, list({a}), Value()),
                       sb ? b : make_series(SeriesKind::Given, list({b}), Value()));
  case BinaryOp::Sub:
    return series_binary(BinaryOp::Add, a, sb ? series_unary(UnaryOp::Neg, b) : g_neg(b));
  case BinaryOp::Mul:
    if (sa && sb) return make_series(SeriesKind::Product, a, b);
    return make_series(SeriesKind::Scale, sa ? b : a, sa ? a : b);
  case BinaryOp::Div:
    if (sa && !sb) return make_series(SeriesKind::Scale, g_unary(UnaryOp::Invert, b), a);
    return make_series(SeriesKind::Quotient, sa ? a : constant_series(a), b);
  case BinaryOp::Expt: return series_expt(a, b);
  default: break;
  }
  arith_wrong_type(op, sa ? b : a, sa ? 2 : 1);
}

bool series_member(Value v) {
  return is_series(v);
}
const ArithType kSeriesArith = {"series", 35, series_member, series_unary, series_binary};

Series *arg_series(Value *a, int i, const char *who) {
  if (!is_series(a[i])) wrong_type(a[i], i + 1, who);
  return as_series(a[i]);
}

// (series:for-each proc series n): proc applied to the first n terms.
Value P_series_for_each(Value *a, int) {
  arg_series(a, 1, "series:for-each");
  size_t n = arg_index(a, 2, "series:for-each");
  for (size_t k = 0; k < n; ++k) {
    Value t = series_term(a[1], k);
    apply_procedure(a[0], &t, 1);
  }
  return Value::unspecified();
}

Value P_series_print(Value *a, int) {
  arg_series(a, 0, "series:print");
  size_t n = arg_index(a, 1, "series:print");
  for (size_t k = 0; k < n; ++k) {
    output(write_string(series_term(a[0], k)));
    output("\n");
  }
  return Value::unspecified();
}

Value P_series_ref(Value *a, int) {
  arg_series(a, 0, "series:ref");
  return series_term(a[0], arg_index(a, 1, "series:ref"));
}

// (series:sum series n): the partial sum of terms 0 through n (n + 1 terms),
// as scmutils defines it.
Value P_series_sum(Value *a, int) {
  arg_series(a, 0, "series:sum");
  size_t n = arg_index(a, 1, "series:sum");
  Value sum = Value::fixnum(0);
  for (size_t k = 0; k <= n; ++k)
    sum = g_add(sum, series_term(a[0], k));
  return sum;
}

Value P_series(Value *a, int n) {
  return make_series(SeriesKind::Given, list_from(a, static_cast<size_t>(n)), Value());
}

Value P_series_p(Value *a, int) {
  return Value::boolean(is_series(a[0]));
}

} // namespace

bool is_series(Value v) {
  return v.is(Tag::Opaque) && v.as<Opaque>()->kind == &kSeriesKind;
}

Value series_term(Value v, size_t k) {
  Series *s = as_series(v);
  while (s->terms.size() <= k)
    s->terms.push_back(compute_term(s, s->terms.size()));
  return s->terms[k];
}

Value make_exp_series(Value op, Value f) {
  return make_series(is_series(f) ? SeriesKind::ExpOfSeries : SeriesKind::Exp, op, f);
}

void install_series_primitives() {
  register_arith_type(&kSeriesArith);
  define_primitive("series:for-each", 3, 3, Stage::Effect, P_series_for_each);
  define_primitive("series:print", 2, 2, Stage::Effect, P_series_print);
  define_primitive("series:ref", 2, 2, Stage::Pure, P_series_ref);
  define_primitive("series:sum", 2, 2, Stage::Pure, P_series_sum);
  define_primitive("series", 0, kVariadic, Stage::Pure, P_series);
  define_primitive("series?", 1, 1, Stage::Pure, P_series_p);
}

} // namespace sicm
