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
#include "eval/core.hpp"
#include "eval/number.hpp"
#include "eval/primitive.hpp"
#include "eval/procedure.hpp"
#include "print/printer.hpp"

namespace sicm {

namespace {

enum class SeriesKind {
  Exp,      // a: operator x, b: function f; powers: x^k f
  Applied,  // a: series of functions, b: argument list
  Sum,      // a + b
  Scale,    // coefficient a times series b
  Product,  // Cauchy product of a and b
  Quotient, // a / b: the series c with c b = a, term by term (b's first term not zero)
  Given,    // the terms listed, then zeros
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

Value series_apply(void *obj, Value *args, int nargs) {
  Value self = Value::object(Tag::Opaque, gc_new<Opaque>(Opaque{&kSeriesKind, obj}));
  return make_series(SeriesKind::Applied, self, list_from(args, static_cast<size_t>(nargs)));
}

Value constant_series(Value x) {
  return make_series(SeriesKind::Given, list({x}), Value());
}

Value series_unary(UnaryOp op, Value x) {
  if (op == UnaryOp::Neg) return make_series(SeriesKind::Scale, Value::fixnum(-1), x);
  if (op == UnaryOp::Invert)
    return make_series(SeriesKind::Quotient, constant_series(Value::fixnum(1)), x);
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
  return make_series(SeriesKind::Exp, op, f);
}

void install_series_primitives() {
  register_arith_type(&kSeriesArith);
  define_primitive("series:for-each", 3, 3, P_series_for_each);
  define_primitive("series:print", 2, 2, P_series_print);
  define_primitive("series:ref", 2, 2, P_series_ref);
  define_primitive("series:sum", 2, 2, P_series_sum);
  define_primitive("series", 0, kVariadic, P_series);
  define_primitive("series?", 1, 1, P_series_p);
}

} // namespace sicm
