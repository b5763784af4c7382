// The numeric primitives of Scheme (+, <, floor, exact->inexact, number->string, random, ...) over
// the numeric tower of number.cpp.
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>

#include "base/error.hpp"
#include "base/number.hpp"
#include "base/number_internal.hpp"
#include "base/primitive.hpp"
#include "builtins/builtins.hpp"
#include "eval/effect_guard.hpp"

namespace sicm {

// ---- primitives -----------------------------------------------------------------------------

namespace {

Value boolean(bool b) {
  return Value::boolean(b);
}

// (+ ...) and (* ...): a left fold from the identity, so that the accumulated
// value is the first argument of MIT's binary integer-add in error messages.
template <Value (*F)(Value, Value)>
Value fold(Value *args, int n, Value identity, const char *who) {
  if (n == 1) check_number(args[0], 1, who);
  Value acc = n == 0 ? identity : args[0];
  for (int i = 1; i < n; i++)
    acc = F(acc, args[i]);
  return acc;
}

Value prim_add(Value *args, int n) {
  return fold<num_add>(args, n, Value::fixnum(0), "integer-add");
}
Value prim_mul(Value *args, int n) {
  return fold<num_mul>(args, n, Value::fixnum(1), "integer-multiply");
}

Value prim_sub(Value *args, int n) {
  if (n == 1) return num_neg(args[0]);
  return fold<num_sub>(args, n, Value::fixnum(0), "integer-subtract");
}

Value prim_div(Value *args, int n) {
  if (n == 1) return num_div(Value::fixnum(1), args[0]);
  return fold<num_div>(args, n, Value::fixnum(1), "/");
}

// Comparisons chain pairwise and stop at the first false pair, as MIT's do.
// MIT computes (> a b) as (integer-less? b a) and (<= a b) as (not (< b a)),
// so those name their arguments in swapped positions.
enum class Cmp { Eq, Lt, Gt, Le, Ge };

bool compare_pair(Cmp how, Value a, Value b) {
  if (how == Cmp::Eq) return num_equal(a, b);
  bool swapped = how == Cmp::Gt || how == Cmp::Le;
  int c = swapped ? num_compare(b, a) : num_compare(a, b);
  if (c == 2) return false; // NaN is unordered
  return how == Cmp::Lt || how == Cmp::Gt ? c < 0 : c >= 0;
}

template <Cmp How> Value compare_chain(Value *args, int n) {
  const char *who = How == Cmp::Eq ? "integer-equal?" : "integer-less?";
  if (n == 1) check_number(args[0], 1, who);
  for (int i = 0; i + 1 < n; i++)
    if (!compare_pair(How, args[i], args[i + 1])) return boolean(false);
  return boolean(true);
}

// MIT's max/min: a NaN loses against a number, and any inexact argument makes
// the result inexact.
Value max_min(Value *args, int n, bool max, const char *who) {
  bool inexact = false;
  for (int i = 0; i < n; i++) {
    check_number(args[i], i + 1, who);
    inexact = inexact || is_flonum(args[i]);
  }
  Value best = args[0];
  for (int i = 1; i < n; i++) {
    int c = compare_numbers(args[i], best);
    bool best_nan = is_flonum(best) && std::isnan(best.d);
    if (best_nan || (c != 2 && (max ? c > 0 : c < 0))) best = args[i];
  }
  return inexact ? num_exact_to_inexact(best) : best;
}

Value prim_max(Value *args, int n) {
  return max_min(args, n, true, "max");
}
Value prim_min(Value *args, int n) {
  return max_min(args, n, false, "min");
}

template <Value (*F)(Value, Value)> Value binary(Value *args, int) {
  return F(args[0], args[1]);
}
template <Value (*F)(Value)> Value unary(Value *args, int) {
  return F(args[0]);
}

template <Value (*F)(Value, Value)> Value fold_gcd(Value *args, int n, Value identity) {
  Value acc = identity;
  for (int i = 0; i < n; i++)
    acc = F(acc, args[i]);
  return acc;
}
Value prim_gcd(Value *args, int n) {
  return fold_gcd<num_gcd>(args, n, Value::fixnum(0));
}
Value prim_lcm(Value *args, int n) {
  return fold_gcd<num_lcm>(args, n, Value::fixnum(1));
}

Value prim_integer_floor(Value *a, int) {
  return integer_divide(Div::Floor, a[0], a[1], "integer-floor");
}
Value prim_integer_ceiling(Value *a, int) {
  return integer_divide(Div::Ceiling, a[0], a[1], "integer-ceiling");
}
Value prim_integer_round(Value *a, int) {
  return integer_divide(Div::Round, a[0], a[1], "integer-round");
}
Value prim_integer_truncate(Value *a, int) {
  return integer_divide(Div::Quotient, a[0], a[1], "integer-truncate");
}

// floor->exact and friends: the rounded value as an exact integer.
template <Value (*Round)(Value)> Value rounded_exact(Value *args, int, const char *who) {
  Value r = Round(args[0]);
  if (is_flonum(r) && !std::isfinite(r.d)) wrong_type(args[0], 1, who);
  return num_inexact_to_exact(r);
}
Value prim_floor_exact(Value *a, int n) {
  return rounded_exact<num_floor>(a, n, "floor->exact");
}
Value prim_ceiling_exact(Value *a, int n) {
  return rounded_exact<num_ceiling>(a, n, "ceiling->exact");
}
Value prim_round_exact(Value *a, int n) {
  return rounded_exact<num_round>(a, n, "round->exact");
}
Value prim_truncate_exact(Value *a, int n) {
  return rounded_exact<num_truncate>(a, n, "truncate->exact");
}

Value prim_number_p(Value *a, int) {
  return boolean(is_number(a[0]));
}
Value prim_integer_p(Value *a, int) {
  return boolean(is_integer(a[0]));
}
Value prim_rational_p(Value *a, int) {
  return boolean(is_exact_rational(a[0]) || (is_flonum(a[0]) && std::isfinite(a[0].d)));
}
Value prim_real_p(Value *a, int) {
  return boolean(is_real(a[0]));
}
Value prim_exact_p(Value *a, int) {
  if (!is_number(a[0])) wrong_type(a[0], 1, "exact?");
  return boolean(is_exact(a[0]));
}
Value prim_inexact_p(Value *a, int) {
  if (!is_number(a[0])) wrong_type(a[0], 1, "inexact?");
  return boolean(!is_exact(a[0]));
}
Value prim_exact_rational_p(Value *a, int) {
  return boolean(is_exact_rational(a[0]));
}
Value prim_exact_integer_p(Value *a, int) {
  return boolean(is_exact_integer(a[0]));
}
Value prim_exact_nonneg_p(Value *a, int) {
  return boolean(is_exact_integer(a[0]) && num_sign(a[0]) >= 0);
}
Value prim_nan_p(Value *a, int) {
  check_number(a[0], 1, "nan?");
  return boolean(is_flonum(a[0]) && std::isnan(a[0].d));
}

Value prim_zero_p(Value *a, int) {
  return boolean(num_is_zero(a[0]));
}
Value prim_positive_p(Value *a, int) {
  check_number(a[0], 1, "positive?");
  return boolean(num_sign(a[0]) > 0);
}
Value prim_negative_p(Value *a, int) {
  check_number(a[0], 1, "negative?");
  return boolean(num_sign(a[0]) < 0);
}

bool is_odd(Value v) {
  Value r = integer_divide(Div::Remainder, v, Value::fixnum(2), "integer-remainder");
  return !num_is_zero(r);
}
Value prim_odd_p(Value *a, int) {
  return boolean(is_odd(a[0]));
}
Value prim_even_p(Value *a, int) {
  return boolean(!is_odd(a[0]));
}

Value prim_one_plus(Value *a, int) {
  return num_add(a[0], Value::fixnum(1));
}
Value prim_minus_one_plus(Value *a, int) {
  return num_sub(a[0], Value::fixnum(1));
}
Value prim_square(Value *a, int) {
  return num_mul(a[0], a[0]);
}
Value prim_cube(Value *a, int) {
  return num_mul(a[0], num_mul(a[0], a[0]));
}

Value prim_atan(Value *a, int n) {
  return n == 2 ? num_atan2(a[0], a[1]) : num_atan(a[0]);
}

Value prim_exact_integer_sqrt(Value *a, int) {
  auto [s, r] = num_exact_integer_sqrt(a[0]);
  auto *mv = gc_new<MultipleValues>();
  mv->items = static_cast<Value *>(GC_MALLOC(2 * sizeof(Value)));
  if (!mv->items) throw std::bad_alloc();
  mv->items[0] = s;
  mv->items[1] = r;
  mv->len = 2;
  return Value::object(Tag::Values, mv);
}

int radix_arg(Value *args, int n, int i, const char *who) {
  if (n <= i || args[i].tag == Tag::Default) return 10;
  auto r = to_int64(args[i]);
  if (!r || *r < 2 || *r > 36) bad_range(args[i], i + 1, who);
  return static_cast<int>(*r);
}

Value prim_number_to_string(Value *a, int n) {
  if (!is_number(a[0])) wrong_type(a[0], 1, "number->string");
  return make_string(number_to_string(a[0], radix_arg(a, n, 1, "number->string")));
}

Value prim_string_to_number(Value *a, int n) {
  std::string_view s = arg_string(a, 0, "string->number");
  auto v = parse_number(s, radix_arg(a, n, 1, "string->number"));
  return v ? *v : boolean(false);
}

// ---- random ----

std::mt19937_64 &random_source() {
  static std::mt19937_64 source(0x5eed5eedULL); // fixed, so runs are reproducible
  return source;
}

// Uniform in [0, n) for n > 0, without modulo bias.
uint64_t random_below(uint64_t n) {
  uint64_t limit = UINT64_MAX - UINT64_MAX % n;
  for (;;) {
    uint64_t r = random_source()();
    if (r < limit) return r % n;
  }
}

Value random_bignum(mpz_srcptr n) {
  size_t bits = mpz_sizeinbase(n, 2);
  size_t words = (bits + 63) / 64;
  std::vector<uint64_t> buf(words);
  Z r;
  do {
    for (auto &w : buf)
      w = random_source()();
    mpz_import(r, words, -1, sizeof(uint64_t), 0, 0, buf.data());
    mpz_fdiv_r_2exp(r, r, bits);
  } while (mpz_cmp(r, n) >= 0);
  return make_integer(r);
}

double random_flonum(double limit) {
  for (;;) {
    double u = static_cast<double>(random_source()() >> 11) * 0x1p-53;
    double r = u * limit;
    if (r < limit) return r;
  }
}

Value prim_random(Value *a, int) {
  refuse_effect("random");
  Value n = a[0];
  if (is_flonum(n)) {
    if (!(n.d > 0) || !std::isfinite(n.d)) bad_range(n, 1, "random");
    return Value::flonum(random_flonum(n.d));
  }
  if (!is_exact_integer(n)) wrong_type(n, 1, "random");
  if (num_sign(n) <= 0) bad_range(n, 1, "random");
  if (n.tag == Tag::Fixnum) return Value::fixnum(static_cast<int64_t>(random_below(n.i)));
  return random_bignum(big(n));
}

struct PrimitiveSpec {
  const char *name;
  int min_args, max_args;
  PrimFn fn;
  Stage stage = Stage::Pure; // arithmetic; the one exception says so in its row
};

const PrimitiveSpec kArithmetic[] = {
    {"+", 0, kVariadic, prim_add},
    {"*", 0, kVariadic, prim_mul},
    {"-", 1, kVariadic, prim_sub},
    {"/", 1, kVariadic, prim_div},
    {"=", 1, kVariadic, compare_chain<Cmp::Eq>},
    {"<", 1, kVariadic, compare_chain<Cmp::Lt>},
    {">", 1, kVariadic, compare_chain<Cmp::Gt>},
    {"<=", 1, kVariadic, compare_chain<Cmp::Le>},
    {">=", 1, kVariadic, compare_chain<Cmp::Ge>},
    {"max", 1, kVariadic, prim_max},
    {"min", 1, kVariadic, prim_min},
    {"quotient", 2, 2, binary<num_quotient>},
    {"remainder", 2, 2, binary<num_remainder>},
    {"modulo", 2, 2, binary<num_modulo>},
    {"gcd", 0, kVariadic, prim_gcd},
    {"lcm", 0, kVariadic, prim_lcm},
    {"integer-floor", 2, 2, prim_integer_floor},
    {"integer-ceiling", 2, 2, prim_integer_ceiling},
    {"integer-round", 2, 2, prim_integer_round},
    {"integer-truncate", 2, 2, prim_integer_truncate},
    {"abs", 1, 1, unary<num_abs>},
    {"magnitude", 1, 1, unary<num_magnitude>},
    {"1+", 1, 1, prim_one_plus},
    {"-1+", 1, 1, prim_minus_one_plus},
    {"1-", 1, 1, prim_minus_one_plus},
    {"square", 1, 1, prim_square},
    {"cube", 1, 1, prim_cube},
};

const PrimitiveSpec kRounding[] = {
    {"floor", 1, 1, unary<num_floor>},
    {"ceiling", 1, 1, unary<num_ceiling>},
    {"round", 1, 1, unary<num_round>},
    {"truncate", 1, 1, unary<num_truncate>},
    {"floor->exact", 1, 1, prim_floor_exact},
    {"ceiling->exact", 1, 1, prim_ceiling_exact},
    {"round->exact", 1, 1, prim_round_exact},
    {"truncate->exact", 1, 1, prim_truncate_exact},
    {"numerator", 1, 1, unary<num_numerator>},
    {"denominator", 1, 1, unary<num_denominator>},
    {"exact->inexact", 1, 1, unary<num_exact_to_inexact>},
    {"inexact->exact", 1, 1, unary<num_inexact_to_exact>},
    {"exact", 1, 1, unary<num_inexact_to_exact>},
    {"inexact", 1, 1, unary<num_exact_to_inexact>},
};

const PrimitiveSpec kPredicates[] = {
    {"number?", 1, 1, prim_number_p},
    {"complex?", 1, 1, prim_number_p},
    {"real?", 1, 1, prim_real_p},
    {"rational?", 1, 1, prim_rational_p},
    {"integer?", 1, 1, prim_integer_p},
    {"exact?", 1, 1, prim_exact_p},
    {"inexact?", 1, 1, prim_inexact_p},
    {"exact-rational?", 1, 1, prim_exact_rational_p},
    {"exact-integer?", 1, 1, prim_exact_integer_p},
    {"exact-nonnegative-integer?", 1, 1, prim_exact_nonneg_p},
    {"nan?", 1, 1, prim_nan_p},
    {"zero?", 1, 1, prim_zero_p},
    {"positive?", 1, 1, prim_positive_p},
    {"negative?", 1, 1, prim_negative_p},
    {"odd?", 1, 1, prim_odd_p},
    {"even?", 1, 1, prim_even_p},
};

const PrimitiveSpec kFunctions[] = {
    {"expt", 2, 2, binary<num_expt>},
    {"sqrt", 1, 1, unary<num_sqrt>},
    {"exact-integer-sqrt", 1, 1, prim_exact_integer_sqrt},
    {"exp", 1, 1, unary<num_exp>},
    {"log", 1, 1, unary<num_log>},
    {"sin", 1, 1, unary<num_sin>},
    {"cos", 1, 1, unary<num_cos>},
    {"tan", 1, 1, unary<num_tan>},
    {"asin", 1, 1, unary<num_asin>},
    {"acos", 1, 1, unary<num_acos>},
    {"atan", 1, 2, prim_atan},
    {"make-rectangular", 2, 2, binary<make_rectangular>},
    {"make-polar", 2, 2, binary<make_polar>},
    {"real-part", 1, 1, unary<num_real_part>},
    {"imag-part", 1, 1, unary<num_imag_part>},
    {"angle", 1, 1, unary<num_angle>},
    {"conjugate", 1, 1, unary<num_conjugate>},
    {"number->string", 1, 2, prim_number_to_string},
    {"string->number", 1, 2, prim_string_to_number},
    {"random", 1, 2, prim_random, Stage::Effect},
};

template <size_t N> void install(const PrimitiveSpec (&specs)[N]) {
  for (const auto &s : specs)
    define_primitive(s.name, s.min_args, s.max_args, s.stage, s.fn);
}

} // namespace

void install_number_primitives() {
  install(kArithmetic);
  install(kRounding);
  install(kPredicates);
  install(kFunctions);
}

} // namespace sicm
