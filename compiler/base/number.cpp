// The numeric tower (fixnums, GMP bignums and ratnums, flonums) with MIT
// Scheme's arithmetic; recnums (complex numbers) are in complex.cpp, and the
// operations here hand them over. Reading and writing numbers is
// number_text.cpp.
#include "base/number.hpp"

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <vector>

#include "base/error.hpp"
#include "base/number_internal.hpp"
#include "base/primitive.hpp"
#include "sicm/runtime.h"

namespace sicm {

static_assert(sizeof(long) == sizeof(int64_t), "GMP's _si functions must take an int64");

[[noreturn]] void divide_by_zero(const char *who) {
  runtime_error(current_call_loc(), std::string("Division by zero signalled by ") + who + ".");
}

namespace {

// ---- errors -----------------------------------------------------------------

// ---- representation -----------------------------------------------------------

// GMP keeps limbs in malloc'd memory, so the boxes hold no collectable
// pointers (atomic) and a finalizer frees the limbs with the box.
void clear_bignum(void *obj, void *) {
  mpz_clear(static_cast<Bignum *>(obj)->z);
}
void clear_ratnum(void *obj, void *) {
  mpq_clear(static_cast<Ratnum *>(obj)->q);
}

template <class T> T *alloc_box() {
  auto *box = static_cast<T *>(GC_MALLOC_ATOMIC(sizeof(T)));
  if (!box) throw std::bad_alloc();
  return box;
}

Value box_bignum(mpz_srcptr z) {
  auto *b = alloc_box<Bignum>();
  mpz_init_set(b->z, z);
  GC_register_finalizer_no_order(b, clear_bignum, nullptr, nullptr, nullptr);
  return Value::object(Tag::Bignum, b);
}

// q must be canonical with a denominator other than 1.
Value box_ratnum(mpq_srcptr q) {
  auto *r = alloc_box<Ratnum>();
  mpq_init(r->q);
  mpq_set(r->q, q);
  GC_register_finalizer_no_order(r, clear_ratnum, nullptr, nullptr, nullptr);
  return Value::object(Tag::Ratnum, r);
}

bool is_exact_zero(Value v) {
  return v.tag == Tag::Fixnum && v.i == 0;
}

// Copy an exact integer into z.
void to_mpz(Value v, mpz_ptr z) {
  if (v.tag == Tag::Fixnum)
    mpz_set_si(z, v.i);
  else
    mpz_set(z, big(v));
}

// ---- correctly rounded conversion to double -------------------------------------

// Round (q + tail) * 2^exp2 to the nearest double, ties to even, where q > 0
// and `sticky` says whether a tail in (0, 1) was dropped. Handles overflow
// (ldexp gives infinity) and gradual underflow (the lsb never goes below 2^-1074).
double round_to_double(mpz_srcptr q, bool sticky, long exp2) {
  long len = static_cast<long>(mpz_sizeinbase(q, 2));
  long lsb = std::max(exp2 + len - 53, -1074L);
  long shift = lsb - exp2;
  if (shift <= 0) return std::ldexp(mpz_get_d(q), static_cast<int>(exp2));
  Z m;
  mpz_tdiv_q_2exp(m, q, static_cast<mp_bitcnt_t>(shift));
  bool half = mpz_tstbit(q, static_cast<mp_bitcnt_t>(shift - 1));
  bool below = sticky || mpz_scan1(q, 0) < static_cast<mp_bitcnt_t>(shift - 1);
  if (half && (below || mpz_odd_p(m.v))) mpz_add_ui(m, m, 1);
  if (lsb > 2000) return HUGE_VAL; // keep ldexp's int argument in range
  return std::ldexp(mpz_get_d(m), static_cast<int>(lsb));
}

double mpz_to_double(mpz_srcptr z) {
  if (mpz_sgn(z) == 0) return 0.0;
  Z a;
  mpz_abs(a, z);
  double d = round_to_double(a, false, 0);
  return mpz_sgn(z) < 0 ? -d : d;
}

// n/d scaled so that the quotient has at least 55 bits, leaving a round bit
// and a sticky bit below the 53 that are kept.
double mpq_to_double(mpq_srcptr q) {
  if (mpq_sgn(q) == 0) return 0.0;
  Z n, quo, r;
  mpz_abs(n, mpq_numref(q));
  long nbits = static_cast<long>(mpz_sizeinbase(n, 2));
  long dbits = static_cast<long>(mpz_sizeinbase(mpq_denref(q), 2));
  long scale = std::max(0L, 55 + dbits - nbits);
  mpz_mul_2exp(n, n, static_cast<mp_bitcnt_t>(scale));
  mpz_tdiv_qr(quo, r, n, mpq_denref(q));
  double d = round_to_double(quo, mpz_sgn(r.v) != 0, -scale);
  return mpq_sgn(q) < 0 ? -d : d;
}

// ---- generic dispatch helpers ----------------------------------------------------

bool either_ratnum(Value a, Value b) {
  return a.tag == Tag::Ratnum || b.tag == Tag::Ratnum;
}

enum class Op { Add, Sub, Mul };

bool fixnum_op(Op op, int64_t a, int64_t b, int64_t *r) {
  switch (op) {
  case Op::Add: return !__builtin_add_overflow(a, b, r);
  case Op::Sub: return !__builtin_sub_overflow(a, b, r);
  case Op::Mul: return !__builtin_mul_overflow(a, b, r);
  }
  return false;
}

double flonum_op(Op op, double a, double b) {
  switch (op) {
  case Op::Add: return a + b;
  case Op::Sub: return a - b;
  case Op::Mul: return a * b;
  }
  return 0;
}

// a op b for exact a and b.
Value exact_op(Op op, Value a, Value b) {
  int64_t r;
  if (a.tag == Tag::Fixnum && b.tag == Tag::Fixnum && fixnum_op(op, a.i, b.i, &r))
    return Value::fixnum(r);
  if (either_ratnum(a, b)) {
    Q x, y, out;
    to_mpq(a, x);
    to_mpq(b, y);
    if (op == Op::Add)
      mpq_add(out, x, y);
    else if (op == Op::Sub)
      mpq_sub(out, x, y);
    else
      mpq_mul(out, x, y);
    return make_rational(out);
  }
  Z x, y, out;
  to_mpz(a, x);
  to_mpz(b, y);
  if (op == Op::Add)
    mpz_add(out, x, y);
  else if (op == Op::Sub)
    mpz_sub(out, x, y);
  else
    mpz_mul(out, x, y);
  return make_integer(out);
}

const char *op_name(Op op) {
  switch (op) {
  case Op::Add: return "integer-add";
  case Op::Sub: return "integer-subtract";
  case Op::Mul: return "integer-multiply";
  }
  return "";
}

// MIT: an exact zero times a finite flonum is an exact zero.
Value arith(Op op, Value a, Value b) {
  if ((is_recnum(a) || is_recnum(b)) && is_number(a) && is_number(b))
    return op == Op::Add   ? complex_add(a, b)
           : op == Op::Sub ? complex_sub(a, b)
                           : complex_mul(a, b);
  check_number(a, 1, op_name(op));
  check_number(b, 2, op_name(op));
  if (!is_flonum(a) && !is_flonum(b)) return exact_op(op, a, b);
  if (op == Op::Mul) {
    if (is_exact_zero(a) && std::isfinite(b.d)) return a;
    if (is_exact_zero(b) && std::isfinite(a.d)) return b;
  }
  return Value::flonum(flonum_op(op, to_double(a), to_double(b)));
}

// Exact comparison of an exact number with a finite flonum.
int compare_exact_flonum(Value a, double d) {
  if (a.tag == Tag::Fixnum && std::abs(a.i) <= (int64_t{1} << 53)) {
    double x = static_cast<double>(a.i);
    return x < d ? -1 : x > d ? 1 : 0;
  }
  Q x, y;
  to_mpq(a, x);
  mpq_set_d(y, d);
  int c = mpq_cmp(x, y);
  return c < 0 ? -1 : c > 0 ? 1 : 0;
}

int compare_doubles(double x, double y) {
  return x < y ? -1 : x > y ? 1 : x == y ? 0 : 2;
}

} // namespace

int compare_numbers(Value a, Value b) {
  if (a.tag == Tag::Fixnum && b.tag == Tag::Fixnum) return a.i < b.i ? -1 : a.i > b.i ? 1 : 0;
  if (is_flonum(a) && is_flonum(b)) return compare_doubles(a.d, b.d);
  if (is_flonum(a) || is_flonum(b)) {
    bool flipped = is_flonum(a);
    Value exact = flipped ? b : a;
    double d = flipped ? a.d : b.d;
    int c = std::isnan(d) ? 2 : std::isinf(d) ? (d > 0 ? -1 : 1) : compare_exact_flonum(exact, d);
    return flipped && c != 2 ? -c : c;
  }
  if (either_ratnum(a, b)) {
    Q x, y;
    to_mpq(a, x);
    to_mpq(b, y);
    int c = mpq_cmp(x, y);
    return c < 0 ? -1 : c > 0 ? 1 : 0;
  }
  Z x, y;
  to_mpz(a, x);
  to_mpz(b, y);
  int c = mpz_cmp(x, y);
  return c < 0 ? -1 : c > 0 ? 1 : 0;
}

// ---- classification -------------------------------------------------------------

bool is_number(Value v) {
  return is_real(v) || v.tag == Tag::Recnum;
}
bool is_exact(Value v) {
  if (v.tag == Tag::Recnum)
    return is_exact_rational(v.as<Recnum>()->re) && is_exact_rational(v.as<Recnum>()->im);
  return is_exact_rational(v);
}
bool is_exact_integer(Value v) {
  return v.tag == Tag::Fixnum || v.tag == Tag::Bignum;
}
bool is_exact_rational(Value v) {
  return is_exact_integer(v) || v.tag == Tag::Ratnum;
}
bool is_integer(Value v) {
  return is_exact_integer(v) || (is_flonum(v) && std::isfinite(v.d) && v.d == std::floor(v.d));
}
bool is_real(Value v) {
  return v.tag == Tag::Fixnum || v.tag == Tag::Flonum || v.tag == Tag::Bignum ||
         v.tag == Tag::Ratnum;
}

// ---- construction -----------------------------------------------------------------

Value make_integer(const mpz_t z) {
  if (mpz_fits_slong_p(z)) return Value::fixnum(mpz_get_si(z));
  return box_bignum(z);
}

Value make_rational(const mpq_t q) {
  Q c;
  mpq_set(c, q);
  mpq_canonicalize(c);
  return make_canonical_rational(c);
}

Value make_canonical_rational(mpq_srcptr q) {
  if (mpz_cmp_ui(mpq_denref(q), 1) == 0) return make_integer(mpq_numref(q));
  return box_ratnum(q);
}

Value make_integer_from_string(std::string_view digits, int radix) {
  std::string s(digits);
  if (!s.empty() && s[0] == '+') s.erase(0, 1);
  Z z;
  SICM_ASSERT(mpz_set_str(z, s.c_str(), radix) == 0);
  return make_integer(z);
}

double to_double(Value v) {
  switch (v.tag) {
  case Tag::Fixnum: return static_cast<double>(v.i);
  case Tag::Flonum: return v.d;
  case Tag::Bignum: return mpz_to_double(big(v));
  case Tag::Ratnum: return mpq_to_double(rat(v));
  default: wrong_type(v, 1, "integer->flonum");
  }
}

std::optional<int64_t> to_int64(Value v) {
  if (v.tag == Tag::Fixnum) return v.i;
  return std::nullopt; // bignums never fit: they are normalized
}

void to_mpq(Value v, mpq_t q) {
  switch (v.tag) {
  case Tag::Fixnum: mpq_set_si(q, v.i, 1); break;
  case Tag::Bignum: mpq_set_z(q, big(v)); break;
  case Tag::Ratnum: mpq_set(q, rat(v)); break;
  default: wrong_type(v, 1, "integer->flonum");
  }
}

// ---- arithmetic ---------------------------------------------------------------------

Value num_add(Value a, Value b) {
  return arith(Op::Add, a, b);
}
Value num_sub(Value a, Value b) {
  return arith(Op::Sub, a, b);
}
Value num_mul(Value a, Value b) {
  return arith(Op::Mul, a, b);
}

// MIT: an exact zero divided by a flonum other than NaN is an exact zero, and
// division by any zero, exact or not, is an error.
Value num_div(Value a, Value b) {
  if ((is_recnum(a) || is_recnum(b)) && is_number(a) && is_number(b)) {
    if (num_is_zero(b)) divide_by_zero("/");
    return complex_div(a, b);
  }
  check_number(a, 1, "/");
  check_number(b, 2, "/");
  if (is_exact_zero(a) && is_flonum(b) && !std::isnan(b.d)) return a;
  if (num_is_zero(b)) divide_by_zero("/");
  if (is_flonum(a) || is_flonum(b)) return Value::flonum(to_double(a) / to_double(b));
  Q x, y, out;
  to_mpq(a, x);
  to_mpq(b, y);
  mpq_div(out, x, y);
  return make_rational(out);
}

Value num_neg(Value a) {
  if (is_recnum(a)) return complex_sub(Value::fixnum(0), a);
  check_number(a, 1, "integer-negate");
  if (is_flonum(a)) return Value::flonum(-a.d);
  return exact_op(Op::Sub, Value::fixnum(0), a);
}

int num_compare(Value a, Value b) {
  check_number(a, 1, "integer-less?");
  check_number(b, 2, "integer-less?");
  return compare_numbers(a, b);
}

bool num_equal(Value a, Value b) {
  if ((is_recnum(a) || is_recnum(b)) && is_number(a) && is_number(b)) return complex_equal(a, b);
  check_number(a, 1, "integer-equal?");
  check_number(b, 2, "integer-equal?");
  return compare_numbers(a, b) == 0;
}

bool num_is_zero(Value a) {
  if (is_recnum(a)) return complex_is_zero(a);
  check_number(a, 1, "zero?");
  return is_flonum(a) ? a.d == 0 : is_exact_zero(a);
}

int num_sign(Value a) {
  check_number(a, 1, "positive?");
  switch (a.tag) {
  case Tag::Fixnum: return a.i < 0 ? -1 : a.i > 0;
  case Tag::Flonum: return a.d < 0 ? -1 : a.d > 0; // NaN: 0
  case Tag::Bignum: return mpz_sgn(big(a));
  default: return mpq_sgn(rat(a));
  }
}

Value num_abs(Value a) {
  check_number(a, 1, "integer-abs");
  if (is_flonum(a)) return Value::flonum(std::fabs(a.d));
  return num_sign(a) < 0 ? num_neg(a) : a;
}

// ---- integer division ---------------------------------------------------------------

namespace {

// An integer argument (exact, or an integral flonum) as an mpz.
void integer_arg(Value v, int argpos, const char *who, mpz_ptr out) {
  if (is_exact_integer(v)) return to_mpz(v, out);
  if (!is_flonum(v) || !is_integer(v)) wrong_type(v, argpos, who);
  flonum_to_mpz(v.d, out);
}

// Rounds n/d to the nearest integer, ties to even.
void round_quotient(mpz_ptr q, mpz_srcptr n, mpz_srcptr d) {
  Z r, twice;
  mpz_fdiv_qr(q, r, n, d); // r has d's sign
  mpz_mul_2exp(twice, r, 1);
  int c = mpz_cmpabs(twice, d);
  if (c > 0 || (c == 0 && mpz_odd_p(q))) mpz_add_ui(q, q, 1);
}

void divide_exact(Div kind, mpz_ptr out, mpz_srcptr n, mpz_srcptr d) {
  switch (kind) {
  case Div::Quotient: mpz_tdiv_q(out, n, d); break;
  case Div::Remainder: mpz_tdiv_r(out, n, d); break;
  case Div::Modulo: mpz_fdiv_r(out, n, d); break;
  case Div::Floor: mpz_fdiv_q(out, n, d); break;
  case Div::Ceiling: mpz_cdiv_q(out, n, d); break;
  case Div::Round: round_quotient(out, n, d); break;
  }
}

bool divide_fixnums(Div kind, int64_t n, int64_t d, int64_t *out) {
  if (d == -1 && n == INT64_MIN) return false;
  int64_t q = n / d, r = n % d;
  switch (kind) {
  case Div::Quotient: *out = q; return true;
  case Div::Remainder: *out = r; return true;
  case Div::Modulo: *out = (r != 0 && (r < 0) != (d < 0)) ? r + d : r; return true;
  default: return false;
  }
}

} // namespace

// Integer division of any kind, MIT style: flonum arguments must be integral
// and make the result a flonum.
Value integer_divide(Div kind, Value n, Value d, const char *who) {
  int64_t r;
  if (n.tag == Tag::Fixnum && d.tag == Tag::Fixnum && d.i != 0 &&
      divide_fixnums(kind, n.i, d.i, &r))
    return Value::fixnum(r);
  Z x, y, out;
  integer_arg(n, 1, who, x);
  integer_arg(d, 2, who, y);
  if (mpz_sgn(y.v) == 0) divide_by_zero(who);
  divide_exact(kind, out, x, y);
  if (is_flonum(n) || is_flonum(d)) return Value::flonum(mpz_to_double(out));
  return make_integer(out);
}

namespace {

Value integer_gcd_lcm(bool gcd, Value a, Value b) {
  const char *who = gcd ? "gcd" : "lcm";
  Z x, y, out;
  integer_arg(a, 1, who, x);
  integer_arg(b, 2, who, y);
  if (gcd)
    mpz_gcd(out, x, y);
  else
    mpz_lcm(out, x, y);
  if (is_flonum(a) || is_flonum(b)) return Value::flonum(mpz_to_double(out));
  return make_integer(out);
}

} // namespace

Value num_quotient(Value a, Value b) {
  return integer_divide(Div::Quotient, a, b, "integer-quotient");
}
Value num_remainder(Value a, Value b) {
  return integer_divide(Div::Remainder, a, b, "integer-remainder");
}
Value num_modulo(Value a, Value b) {
  return integer_divide(Div::Modulo, a, b, "modulo");
}
Value num_gcd(Value a, Value b) {
  return integer_gcd_lcm(true, a, b);
}
Value num_lcm(Value a, Value b) {
  return integer_gcd_lcm(false, a, b);
}

// ---- rounding -------------------------------------------------------------------------

namespace {

// Rounds a ratnum to an integer with the given kind of integer division.
Value round_ratnum(Value a, Div kind) {
  Z out;
  divide_exact(kind, out, mpq_numref(rat(a)), mpq_denref(rat(a)));
  return make_integer(out);
}

Value round_number(Value a, Div kind, double (*flo)(double), const char *who) {
  check_number(a, 1, who);
  if (is_flonum(a)) return Value::flonum(flo(a.d));
  if (a.tag == Tag::Ratnum) return round_ratnum(a, kind);
  return a;
}

double round_half_even(double x) {
  return std::nearbyint(x);
}
double trunc_double(double x) {
  return std::trunc(x);
}
double floor_double(double x) {
  return std::floor(x);
}
double ceil_double(double x) {
  return std::ceil(x);
}

} // namespace

Value num_floor(Value a) {
  return round_number(a, Div::Floor, floor_double, "floor");
}
Value num_ceiling(Value a) {
  return round_number(a, Div::Ceiling, ceil_double, "ceiling");
}
Value num_round(Value a) {
  return round_number(a, Div::Round, round_half_even, "round");
}
Value num_truncate(Value a) {
  return round_number(a, Div::Quotient, trunc_double, "truncate");
}

namespace {

// numerator/denominator of a flonum are those of the rational it denotes, inexact.
Value flonum_ratio_part(Value a, bool numerator, const char *who) {
  if (!std::isfinite(a.d)) wrong_type(a, 1, who);
  Q q;
  mpq_set_d(q, a.d);
  return Value::flonum(mpz_to_double(numerator ? mpq_numref(q.v) : mpq_denref(q.v)));
}

} // namespace

Value num_numerator(Value a) {
  check_number(a, 1, "numerator");
  if (is_flonum(a)) return flonum_ratio_part(a, true, "numerator");
  if (a.tag == Tag::Ratnum) return make_integer(mpq_numref(rat(a)));
  return a;
}

Value num_denominator(Value a) {
  check_number(a, 1, "denominator");
  if (is_flonum(a)) return flonum_ratio_part(a, false, "denominator");
  if (a.tag == Tag::Ratnum) return make_integer(mpq_denref(rat(a)));
  return Value::fixnum(1);
}

Value num_exact_to_inexact(Value a) {
  if (is_recnum(a)) return complex_exact_to_inexact(a);
  check_number(a, 1, "exact->inexact");
  return is_flonum(a) ? a : Value::flonum(to_double(a));
}

Value num_inexact_to_exact(Value a) {
  if (is_recnum(a)) return complex_inexact_to_exact(a);
  check_number(a, 1, "inexact->exact");
  if (!is_flonum(a)) return a;
  if (!std::isfinite(a.d)) wrong_type(a, 1, "inexact->exact");
  Q q;
  mpq_set_d(q, a.d);
  return make_rational(q);
}

// ---- expt and sqrt --------------------------------------------------------------------

namespace {

// x^y for a flonum x and an exact integer y > 0, by MIT's repeated squaring
// (not pow()), so that the last bits agree with MIT.
double flonum_expt_positive(double x, mpz_srcptr exponent) {
  if (mpz_cmp_ui(exponent, 1) == 0) return x;
  Z y;
  mpz_set(y, exponent);
  double answer = 1.0;
  for (;;) {
    bool odd = mpz_odd_p(y.v);
    mpz_fdiv_q_2exp(y, y, 1);
    if (odd) answer *= x;
    x *= x;
    if (mpz_cmp_ui(y.v, 1) == 0) return answer * x;
  }
}

// MIT's flonum expt for the remaining cases.
double flonum_expt_general(double x, double y) {
  if (y == 0) return 1.0;
  if (x == 0) {
    if (y > 0) return x;
    divide_by_zero("expt");
  }
  SICM_ASSERT(!(x < 0 && y != std::floor(y))); // num_expt went complex
  return std::pow(x, y);
}

Value flonum_base_expt(double x, Value e) {
  if (is_flonum(e) || e.tag == Tag::Ratnum)
    return Value::flonum(flonum_expt_general(x, to_double(e)));
  int sign = num_sign(e);
  if (sign == 0) return Value::flonum(1.0);
  Z y;
  to_mpz(e, y);
  if (sign > 0) return Value::flonum(flonum_expt_positive(x, y));
  if (std::fabs(x) < 1) {
    mpz_neg(y, y);
    return Value::flonum(1.0 / flonum_expt_positive(x, y));
  }
  // The sign of a negative base's power is the exponent's parity, which an
  // exponent past 2^53 loses when rounded to a double (always even there):
  // (expt -2.08 -16677181699666569) is -0., as repeated squaring gives it.
  double r = flonum_expt_general(x, to_double(e));
  if (x < 0) r = mpz_odd_p(y.v) ? -std::fabs(r) : std::fabs(r);
  return Value::flonum(r);
}

// Exact base to an exact integer power.
Value exact_integer_expt(Value b, Value e) {
  Z exponent;
  to_mpz(e, exponent);
  bool negative = mpz_sgn(exponent.v) < 0;
  mpz_abs(exponent, exponent);
  Q base, out;
  to_mpq(b, base);
  if (!mpz_fits_ulong_p(exponent)) {
    if (mpz_cmpabs_ui(mpq_numref(base.v), 1) != 0 || mpz_cmp_ui(mpq_denref(base.v), 1) != 0)
      bad_range(e, 2, "expt");
    mpz_set_si(mpq_numref(base.v), mpz_odd_p(exponent.v) ? mpz_get_si(mpq_numref(base.v)) : 1);
    return make_rational(base);
  }
  unsigned long n = mpz_get_ui(exponent);
  // GMP aborts the process when a result outgrows its size field, and a
  // result of more than kMaxPowerBits bits (32 MiB) is a mistake, not a
  // computation: refuse it as MIT refuses what it cannot allocate.
  constexpr double kMaxPowerBits = 268435456.0;
  double bits = static_cast<double>(
      std::max(mpz_sizeinbase(mpq_numref(base.v), 2), mpz_sizeinbase(mpq_denref(base.v), 2)));
  if (bits > 1 && (bits - 1) * static_cast<double>(n) > kMaxPowerBits)
    runtime_error(current_call_loc(),
                  "expt: the exact result would have more than 268435456 bits; use an inexact "
                  "base (exact->inexact) for a flonum result");
  mpz_pow_ui(mpq_numref(out.v), mpq_numref(base.v), n);
  mpz_pow_ui(mpq_denref(out.v), mpq_denref(base.v), n);
  if (negative) mpq_inv(out, out);
  // Powers of coprime integers are coprime: the result is canonical as it
  // is, and canonicalizing a power of millions of bits (a gcd) took minutes.
  return make_canonical_rational(out);
}

// The exact k-th root of a positive exact rational, if there is one.
std::optional<Value> exact_root(Value b, unsigned long k) {
  Q q, out;
  to_mpq(b, q);
  if (!mpz_root(mpq_numref(out.v), mpq_numref(q.v), k)) return std::nullopt;
  if (!mpz_root(mpq_denref(out.v), mpq_denref(q.v), k)) return std::nullopt;
  return make_rational(out);
}

// MIT: an exact base to the power 1/k is exact when the root is; any other
// rational exponent gives a flonum.
Value exact_base_rational_expt(Value b, Value e) {
  mpq_srcptr y = rat(e);
  if (num_sign(b) > 0 && mpz_cmp_ui(mpq_numref(y), 1) == 0 && mpz_fits_ulong_p(mpq_denref(y))) {
    if (auto root = exact_root(b, mpz_get_ui(mpq_denref(y)))) return *root;
  }
  return Value::flonum(flonum_expt_general(to_double(b), to_double(e)));
}

// expt with a zero base, by MIT's rules.
Value zero_base_expt(Value b, Value e) {
  if (is_exact_zero(e)) return Value::fixnum(1);
  int sign = num_sign(e);
  if (sign > 0 && !is_flonum(b)) return Value::fixnum(0);
  if (sign > 0) {
    // The sign of a flonum zero's power is the exponent's parity, as
    // repeated multiplication gives it: (expt -0. 12) is 0., (expt -0. 3)
    // -0.; any other exponent gives 0., as pow does.
    bool odd = false;
    if (is_exact_integer(e)) {
      Z n;
      to_mpz(e, n);
      odd = mpz_odd_p(n.v);
    }
    return Value::flonum(odd ? b.d : 0.0);
  }
  if (sign == 0 && !std::isnan(to_double(e))) bad_range(e, 2, "expt");
  divide_by_zero("expt");
}

} // namespace

Value num_expt(Value base, Value exponent) {
  if ((is_recnum(base) || is_recnum(exponent)) && is_number(base) && is_number(exponent))
    return complex_expt(base, exponent);
  check_number(base, 1, "expt");
  check_number(exponent, 2, "expt");
  if (num_is_zero(base)) return zero_base_expt(base, exponent);
  if (num_sign(base) < 0 && !is_integer(exponent)) return complex_expt(base, exponent);
  if (is_flonum(base)) return flonum_base_expt(base.d, exponent);
  if (is_flonum(exponent)) return Value::flonum(flonum_expt_general(to_double(base), exponent.d));
  if (is_exact_integer(exponent)) return exact_integer_expt(base, exponent);
  return exact_base_rational_expt(base, exponent);
}

Value num_sqrt(Value a) {
  if (is_recnum(a)) return complex_sqrt(a);
  check_number(a, 1, "sqrt");
  if (num_sign(a) < 0) return complex_sqrt(a);
  if (is_flonum(a)) return Value::flonum(std::sqrt(a.d));
  if (auto root = exact_root(a, 2)) return *root;
  return Value::flonum(std::sqrt(to_double(a)));
}

std::pair<Value, Value> num_exact_integer_sqrt(Value n) {
  if (!is_exact_integer(n) || num_sign(n) < 0) wrong_type(n, 1, "exact-integer-sqrt");
  Z x, s, r;
  to_mpz(n, x);
  mpz_sqrtrem(s, r, x);
  return {make_integer(s), make_integer(r)};
}

// ---- transcendental functions ------------------------------------------------------------

namespace {

bool is_exact_one(Value v) {
  return v.tag == Tag::Fixnum && v.i == 1;
}

double real_arg(Value a, const char *who) {
  check_number(a, 1, who);
  return to_double(a);
}

// asin and acos leave the reals outside [-1, 1].
bool outside_unit_interval(Value a, const char *who) {
  double x = real_arg(a, who);
  return x < -1 || x > 1;
}

} // namespace

Value num_exp(Value a) {
  if (is_recnum(a)) return complex_exp(a);
  if (is_exact_zero(a)) return Value::fixnum(1);
  return Value::flonum(std::exp(real_arg(a, "exp")));
}

Value num_log(Value a) {
  if (is_exact_one(a)) return Value::fixnum(0);
  if (is_recnum(a)) return complex_log(a);
  double x = real_arg(a, "log");
  if (x < 0) return complex_log(a);
  if (x == 0) divide_by_zero("log");
  return Value::flonum(std::log(x));
}

Value num_sin(Value a) {
  if (is_recnum(a)) return complex_sin(a);
  if (is_exact_zero(a)) return a;
  return Value::flonum(std::sin(real_arg(a, "sin")));
}

Value num_cos(Value a) {
  if (is_recnum(a)) return complex_cos(a);
  if (is_exact_zero(a)) return Value::fixnum(1);
  return Value::flonum(std::cos(real_arg(a, "cos")));
}

Value num_tan(Value a) {
  if (is_recnum(a)) return complex_tan(a);
  if (is_exact_zero(a)) return a;
  return Value::flonum(std::tan(real_arg(a, "tan")));
}

Value num_asin(Value a) {
  if (is_recnum(a) || outside_unit_interval(a, "asin")) return complex_asin(a);
  if (is_exact_zero(a)) return a;
  return Value::flonum(std::asin(to_double(a)));
}

Value num_acos(Value a) {
  if (is_recnum(a) || outside_unit_interval(a, "acos")) return complex_acos(a);
  if (is_exact_one(a)) return Value::fixnum(0);
  return Value::flonum(std::acos(to_double(a)));
}

Value num_atan(Value a) {
  if (is_recnum(a)) return complex_atan(a);
  if (is_exact_zero(a)) return a;
  return Value::flonum(std::atan(real_arg(a, "atan")));
}

// MIT: an exact zero y with an exact x gives exact 0, or pi when x < 0.
Value num_atan2(Value y, Value x) {
  check_number(y, 1, "atan");
  check_number(x, 2, "atan");
  if (is_exact_zero(y) && is_exact(x))
    return num_sign(x) < 0 ? Value::flonum(std::numbers::pi) : Value::fixnum(0);
  return Value::flonum(std::atan2(to_double(y), to_double(x)));
}

} // namespace sicm
